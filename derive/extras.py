"""What to install for an optional feature, in words that work wherever the user is.

derive-ik is installed from its repository (a checkout or a wheel built from it), not from a
package index, so a hint naming the distribution with an extra in brackets would send pip to
look for it there and fail. A hint therefore names the extra's own packages, read from the
installed distribution's metadata (the requirements marked ``extra == "NAME"``), e.g.
``pip install 'matplotlib==3.11.2' (the plot extra)``.
"""

from __future__ import annotations

import re
from importlib import metadata

DISTRIBUTION = "derive-ik"


def extra_requirements(extra: str) -> tuple[str, ...]:
    """The requirements of one extra (e.g. ``"matplotlib==3.11.2"``), in the metadata's order;
    empty when the distribution is not installed (a bare source tree on sys.path)."""
    try:
        requires = metadata.requires(DISTRIBUTION) or []
    except metadata.PackageNotFoundError:
        return ()
    marker = re.compile(r"""\bextra\s*==\s*["']""" + re.escape(extra) + r"""["']""")
    found: list[str] = []
    for line in requires:
        requirement, _, condition = line.partition(";")
        requirement = requirement.strip()
        if marker.search(condition) and requirement not in found:
            found.append(requirement)
    return tuple(found)


def install_hint(extra: str) -> str:
    """The pip command that installs an extra's packages, e.g. for a missing-import message."""
    packages = extra_requirements(extra)
    if not packages:
        return f"install the derive-ik checkout with its {extra} extra: pip install '.[{extra}]'"
    return "pip install " + " ".join(f"'{p}'" for p in packages) + f" (the {extra} extra)"


def version() -> str:
    """The installed derive-ik's version, or "unknown" for a source tree not installed."""
    try:
        return metadata.version(DISTRIBUTION)
    except metadata.PackageNotFoundError:
        return "unknown"
