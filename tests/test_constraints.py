"""The versions a fresh clone installs are the ones the suite was run with (issue 27, item 19).

``constraints.txt`` pins every distribution of the venv; scripts/setup (and so CI, through
scripts/check) installs with it; pyproject keeps loose ranges for library users.
"""

from __future__ import annotations

import re
import tomllib
from importlib import metadata

from procutil import REPO


def pins() -> dict[str, str]:
    out = {}
    for line in (REPO / "constraints.txt").read_text().splitlines():
        if line and not line.startswith("#"):
            name, _, version = line.partition("==")
            assert version, f"constraints.txt: {line!r} is not NAME==VERSION"
            out[canonical(name)] = version
    return out


def canonical(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def requirements() -> list[str]:
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    wanted = list(project["dependencies"])
    for extra in project["optional-dependencies"].values():
        wanted += extra
    return [canonical(re.split(r"[<>=!~\[; ]", w, maxsplit=1)[0]) for w in wanted]


def test_every_requirement_is_pinned_and_the_venv_has_the_pinned_version() -> None:
    pinned = pins()
    for name in requirements():
        assert name in pinned, f"{name} is required by pyproject.toml but not in constraints.txt"
    for name, version in pinned.items():
        installed = metadata.version(name)
        assert installed == version, (
            f"{name} {installed} is installed, constraints.txt says {version}: run scripts/setup,"
            " or scripts/lock if the change is meant (README, Development)"
        )


def test_pyproject_keeps_ranges_and_setup_installs_the_pins() -> None:
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    assert not any("==" in d for d in project["dependencies"]), project["dependencies"]
    setup = (REPO / "scripts" / "setup").read_text()
    assert "--constraint constraints.txt" in setup
    assert "constraints.txt" in setup.split("want=", 1)[1].splitlines()[0]  # a change reinstalls
    assert "scripts/setup" in (REPO / "scripts" / "check").read_text()
