"""Writing what derive makes: atomically (a temporary file, then a rename), regular files only,
through symbolic links to their targets. Every command's output goes through here."""

from __future__ import annotations

import difflib
import os
import stat
import tempfile
import time
from pathlib import Path


class OutputError(Exception):
    """An output that cannot be written as asked; one line, exit 2."""


TMP_SUFFIX = ".derive-tmp"


# a temporary file this old is a killed run's leftover (a run writes its files in seconds; two
# runs writing into one folder at once keep each other's younger ones)
LEFTOVER_AGE = 60.0


def write_atomic(path: Path, text: str | bytes) -> None:
    """Write through a temporary file and rename, so no partial file is ever visible.

    The file gets the mode an existing file at ``path`` has, else the mode a new file gets
    under the process's umask (0644 under umask 022). Temporary files of earlier runs that
    were killed while writing this file (``.NAME.*.derive-tmp``, LEFTOVER_AGE seconds old:
    a younger one may be another run's, writing now) are removed first. A
    symbolic link at ``path`` is followed (its target is replaced, the link stays); anything
    else that is not a regular file is refused (see output_file).
    """
    path = output_file(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    for leftover in path.parent.glob(f".{path.name}.*{TMP_SUFFIX}"):
        try:
            if leftover.stat().st_mtime < time.time() - LEFTOVER_AGE:
                leftover.unlink(missing_ok=True)
        except FileNotFoundError:  # (its run renamed or removed it meanwhile)
            pass
    try:
        mode = stat.S_IMODE(path.stat().st_mode)
    except FileNotFoundError:
        mode = 0o666 & ~current_umask()
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=TMP_SUFFIX, dir=path.parent)
    except OSError as exc:  # (the user's path in the message, not the temporary file's)
        raise OSError(exc.errno, exc.strerror, str(path)) from None
    try:
        if isinstance(text, bytes):
            with os.fdopen(fd, "wb") as binary:
                binary.write(text)
        else:
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as handle:
                handle.write(text)
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


# what stat's file type is, for the messages refusing it
NODE_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a named pipe (FIFO)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISREG, "a regular file"),
)


def node_kind(mode: int) -> str:
    """What a file of this st_mode is, in words ("a named pipe (FIFO)")."""
    return next((kind for test, kind in NODE_KINDS if test(mode)), "not a regular file")


def output_file(path: Path) -> Path:
    """The file that writing ``path`` replaces: ``path``, or for a symbolic link the file it
    names in the end (the link stays a link; a dangling link's target is created). derive
    replaces regular files only: a folder, a device (/dev/stdout too: ``-o -`` is standard
    output where a command can print), a named pipe or a socket is refused, as is ``-``
    where standard output is not an option."""
    if str(path) == "-":
        raise OutputError("-: this output cannot go to standard output; give a file name")
    try:
        mode = path.stat().st_mode
    except (FileNotFoundError, NotADirectoryError):  # (a folder above it a file: see
        mode = stat.S_IFREG  # existing_folder)
    if not stat.S_ISREG(mode):
        raise OutputError(
            f"{path}: is {node_kind(mode)}; derive writes regular files only (or the "
            "file a symbolic link names), never replaces anything else"
        )
    if not path.is_symlink():
        return path
    target = Path(os.path.realpath(path))
    if not target.parent.is_dir():  # (no folders made where a dangling link points)
        raise OutputError(f"{path}: a symbolic link to {target}, whose folder does not exist")
    return target


def writable_file(path: Path) -> Path:
    """output_file(path), where a file can be made in its folder (or the nearest folder above
    it that exists: write_atomic makes the rest): said before the work, not after it (a new
    user's ``derive path ... -o /proc/p.svg`` printed its table, then named a temporary file
    that could not be made)."""
    target = output_file(path)
    folder = existing_folder(target.parent, str(path))
    try:
        fd, probe = tempfile.mkstemp(prefix=f".{target.name}.", suffix=TMP_SUFFIX, dir=folder)
    except OSError as exc:
        raise OutputError(f"{path}: cannot write there: {exc.strerror}") from None
    os.close(fd)
    Path(probe).unlink(missing_ok=True)
    return target


def existing_folder(folder: Path, what: str) -> Path:
    """The nearest of folder and the folders above it that exists (the rest are made when
    written), refused where that is not a folder (a new user's ``--out afile/g`` got "[Errno
    20] Not a directory: 'afile/g/puma560.py'" after the work)."""
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise OutputError(
            f"{what}: {folder} is {node_kind(folder.stat().st_mode)}, not a folder; no "
            "folder can be made in it"
        )
    return folder


def output_folder(path: Path, option: str) -> Path:
    """A folder to write files into (``option``'s): a folder, or a path where none is yet
    (under a folder: existing_folder)."""
    if str(path) == "-":
        raise OutputError(f"{option} -: {option} names a folder, not standard output")
    if path.exists() and not path.is_dir():
        raise OutputError(
            f"{option} {path}: is {node_kind(path.stat().st_mode)}, not a folder; {option} "
            "names the folder to write into (created if missing)"
        )
    existing_folder(path, f"{option} {path}")
    return path


def current_umask() -> int:
    """The process's umask (read by setting it and setting it back)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


# the most diff lines `derive check` prints for one file
DIFF_LINES = 40


def describe_difference(path: Path, actual: bytes, expected: bytes) -> str:
    """Why a file's bytes differ from the regenerated ones: a unified diff of the lines, or
    what differs when the lines are equal (line endings, encoding)."""
    old = actual.decode("utf-8", errors="replace").splitlines()
    new = expected.decode("utf-8").splitlines()
    if old == new:
        return (
            f"{path}: differs from the regenerated file in bytes, not in lines (line "
            "endings or a byte-order mark; generated files are UTF-8 with \\n newlines)"
        )
    diff = list(difflib.unified_diff(old, new, str(path), f"{path} (regenerated)", lineterm=""))
    shown = "\n".join(diff[:DIFF_LINES])
    more = f"\n... {len(diff) - DIFF_LINES} more diff lines" if len(diff) > DIFF_LINES else ""
    return f"{path}: differs from the regenerated file\n{shown}{more}"
