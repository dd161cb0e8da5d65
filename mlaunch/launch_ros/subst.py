"""The ``$(...)`` language as the readers and launch_ros read it: launch's names (the scanner,
``mlaunch.launch.frontend.template``) plus launch_ros's (``find-pkg-share``, ``find-pkg-prefix``,
``exec-in-pkg``, ``param``).

It sits in launch_ros because it builds launch_ros's substitutions (imported only when a file
uses one), and ``ParameterFile(allow_substs=True)`` reads params files with it; the readers
(mlaunch.frontends) use it from here.
"""

from __future__ import annotations

from mlaunch.launch.frontend.template import (
    SUBSTITUTIONS as LAUNCH_SUBSTITUTIONS,
)
from mlaunch.launch.frontend.template import (
    Part,
    Parts,
    SubstitutionSpec,
    TemplateError,
    has_substitutions,
)
from mlaunch.launch.frontend.template import parse_template as _parse_template

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any


def _ros() -> Any:
    # launch_ros substitutions: imported only when a file uses one.
    import mlaunch.launch_ros.substitutions as ros

    return ros


ROS_SUBSTITUTIONS: dict[str, SubstitutionSpec] = {
    "find-pkg-share": SubstitutionSpec(
        "$(find-pkg-share package)", 1, 1, lambda a: _ros().FindPackageShare(a[0])
    ),
    "find-pkg-prefix": SubstitutionSpec(
        "$(find-pkg-prefix package)", 1, 1, lambda a: _ros().FindPackagePrefix(a[0])
    ),
    "exec-in-pkg": SubstitutionSpec(
        "$(exec-in-pkg executable package)",
        2,
        2,
        lambda a: _ros().ExecutableInPackage(a[0], a[1]),
    ),
    "param": SubstitutionSpec(
        "$(param name [default])",
        1,
        2,
        lambda a: _ros().Parameter(a[0], default=a[1] if len(a) > 1 else None),
    ),
}

# Every name the readers know, launch's and launch_ros's.
SUBSTITUTIONS: dict[str, SubstitutionSpec] = {**LAUNCH_SUBSTITUTIONS, **ROS_SUBSTITUTIONS}


def parse_template(text: str) -> Parts:
    """The parts of an attribute value (text and substitutions), with launch_ros's names."""
    return _parse_template(text, ROS_SUBSTITUTIONS)


__all__ = [
    "ROS_SUBSTITUTIONS",
    "SUBSTITUTIONS",
    "Part",
    "Parts",
    "TemplateError",
    "has_substitutions",
    "parse_template",
]
