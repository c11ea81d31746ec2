"""The formats an arm comes in, behind one registry: each reader lowers a file to the canonical
spec (derive/spec.py's ArmSpec). A new format is one reader here and one line in READERS."""

from __future__ import annotations

import re
from collections.abc import Callable
from importlib import resources
from pathlib import Path

from derive import mjcf, urdf
from derive.spec import ArmSpec, SpecError, load_spec

# a reader: the file and the URDF conversion options (the formats that convert take them)
Reader = Callable[[Path, urdf.Options], ArmSpec]


def _spec_file(path: Path, options: urdf.Options) -> ArmSpec:
    """A spec file (TOML): read and validated as it is."""
    return load_spec(path)


def _xml_file(path: Path, options: urdf.Options) -> ArmSpec:
    """An .xml file: a URDF if its root element is <robot> (URDFs are often named .xml),
    else MJCF (MuJoCo's compiler reads it)."""
    try:
        with path.open("rb") as stream:
            head = stream.read(65536)
    except OSError:
        head = b""  # (the reader says why it cannot read the file)
    root = re.search(rb"<\s*([A-Za-z_][\w.-]*)", re.sub(rb"<[?!][^>]*>", b"", head))
    if root is not None and root.group(1) == b"robot":
        return urdf.load_urdf(path, options)
    if root is not None and root.group(1) == b"sdf":
        raise SpecError(f"{path}: an SDFormat file (its root element is <sdf>); {FORMATS}")
    return mjcf.load_mjcf(path, options)


def _sdf_file(path: Path, options: urdf.Options) -> ArmSpec:
    """An SDFormat file (Gazebo's): refused, naming the formats that are read."""
    raise SpecError(f"{path}: an SDFormat (.sdf) file; {FORMATS}")


# what the readers read, for messages
FORMATS = (
    "derive reads spec files (.toml), URDF (.urdf, or .xml with a <robot> root) and MJCF "
    "(.xml, .mjcf); a file of another suffix is read as XML where it starts with '<'"
)

# file suffix (lower case) -> reader
READERS: dict[str, Reader] = {
    ".sdf": _sdf_file,
    ".toml": _spec_file,
    ".urdf": urdf.load_urdf,
    ".xacro": urdf.load_urdf,  # (it says to expand the file first)
    ".xml": _xml_file,
    ".mjcf": mjcf.load_mjcf,
}


def _starts_with_markup(path: Path) -> bool:
    """Whether the file's first character that is not white space (or a byte order mark) is
    "<": XML, where a spec (TOML) cannot start so. Only a regular file is opened (a named
    pipe would block until a writer came)."""
    if not path.is_file():
        return False
    try:
        with path.open("rb") as stream:
            head = stream.read(4096)
    except OSError:
        return False
    return head.lstrip(b"\xef\xbb\xbf \t\r\n").startswith(b"<")


def conversion_options(options: urdf.Options | None) -> list[str]:
    """The command line options of a conversion that options sets (not to their defaults)."""
    if options is None:
        return []
    default = urdf.Options()
    flags = {"base": "--base", "tip": "--tip", "name": "--name", "exact": "--exact",
             "task": "--task", "tool_axis": "--tool-axis", "angle_tol": "--angle-tol",
             "length_tol": "--length-tol", "max_deviation": "--max-deviation",
             "convention": "--convention", "method": "--method",
             "base_axis": "--base-axis"}  # fmt: skip
    return [flag for key, flag in flags.items() if getattr(options, key) != getattr(default, key)]


def bundled_specs() -> list[Path]:
    """The bundled arm spec files, sorted by name."""
    folder = resources.files("derive.arms")
    return sorted(
        (Path(str(folder)) / p.name for p in folder.iterdir() if p.name.endswith(".toml")),
        key=lambda p: p.name,
    )


def _reader(path: Path) -> Reader | None:
    """The reader of a file by its suffix, or by its root element where that is XML (a URDF
    or MJCF named otherwise, e.g. robot.txt); None for others (a spec or bundled arm name)."""
    reader = READERS.get(path.suffix.lower())
    if reader is None and _starts_with_markup(path):
        reader = _xml_file
    return reader


def converts(text: str) -> bool:
    """Whether text names a URDF or MJCF file: one the conversion's options apply to."""
    reader = _reader(Path(text))
    return reader is not None and reader is not _spec_file


def resolve_spec(text: str, options: urdf.Options | None = None) -> ArmSpec:
    """A spec from a file path (a URDF or MJCF with options' base and tip), or a bundled arm
    by name."""
    path = Path(text)
    reader = _reader(path)
    if reader is None and path.is_dir():
        raise SpecError(f"{text}: a folder, not an arm's file; {FORMATS}")
    if reader is not None and reader is not _spec_file:
        return reader(path, options or urdf.Options())
    if given := conversion_options(options):
        raise SpecError(
            f"{text}: {', '.join(given)}: options of a URDF or MJCF file's conversion, and "
            "this arm is a spec (in a spec, [ik] task, tool_axis, base_axis and method say these)"
        )
    if reader is not None:
        return reader(path, urdf.Options())
    if path.exists():  # (a spec file of another name)
        try:
            return load_spec(path)
        except SpecError as exc:
            if "not valid TOML" not in str(exc):
                raise
            raise SpecError(f"{exc}; {FORMATS}") from None
    for candidate in bundled_specs():
        if candidate.stem == text:
            return load_spec(candidate)
    names = ", ".join(p.stem for p in bundled_specs())
    raise SpecError(f"{text}: no such spec file or bundled arm; bundled arms: {names}")
