"""What an export carries to another computer, and what it cannot: shared by every format.

- ``not_portable``: the processes that run something only this computer has: a stand-in
  (mlaunch's program in place of a package that is not installed here) or a program inside this
  machine's virtual environment or mlaunch's own package folder. One line per process; an export
  refuses them unless ``--allow-standins`` (then they are warnings in its README).
- ``copy_launch_tree``: the launch file's folder (its includes, parameter files, URDFs next to
  it), copied under the export, without version-control folders, caches, linked folders or the
  export itself.
- ``mlaunch_command``: the mlaunch a unit runs (absolute, as systemd wants it).
"""

from __future__ import annotations

import os
import shutil
import sys

from mlaunch.plan.errors import MlaunchError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable

    from mlaunch.export.folder import Folder
    from mlaunch.plan.steps import ProcessSpec

# Folders never copied with a launch tree.
SKIPPED = frozenset({".git", ".hg", ".svn", "__pycache__", ".venv", "venv", "node_modules"})
# A launch tree larger than this is refused: it is not a launch folder (a home, a workspace).
MAX_TREE_BYTES = 64 * 1024 * 1024


class NotPortable(MlaunchError):
    """An export would carry programs only this computer has (without --allow-standins)."""


def local_roots() -> list[str]:
    """Folders whose programs exist only on this computer: the virtual environment mlaunch runs
    in (when it is one) and the mlaunch package it is imported from (a clone's)."""
    roots = []
    if sys.prefix != sys.base_prefix:
        roots.append(os.path.abspath(sys.prefix))  # its python is a link out of it: not resolved
    roots.append(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # mlaunch/
    return roots + [r for r in map(os.path.realpath, roots) if r not in roots]


def not_portable(specs: Iterable[ProcessSpec]) -> list[str]:
    """One line per process that runs a stand-in or a program of this computer's only."""
    roots = local_roots()
    lines = []
    for spec in specs:
        if spec.standin:
            node = spec.node
            real = f"{node.package}/{node.executable}" if node is not None else spec.label
            lines.append(
                f"{spec.label}: runs mlaunch's stand-in {spec.standin!r} because {real} is not"
                " installed here; the robot needs the real package"
            )
            continue
        for word in spec.argv[:2] if not spec.shell else ():
            paths = {os.path.normpath(word), os.path.realpath(word)} if os.path.isabs(word) else ()
            root = next((r for r in roots for p in paths if p.startswith(r + os.sep)), None)
            if root is not None:
                lines.append(
                    f"{spec.label}: runs {word}, inside {root} (this computer's virtual"
                    " environment or mlaunch's own folder); the robot needs it at that path"
                )
                break
    return lines


def check_portable(specs: Iterable[ProcessSpec], allow: bool, warnings: list[str]) -> None:
    """Refuse (NotPortable, every line) unless ``allow``; then the lines become warnings."""
    lines = not_portable(specs)
    if not lines:
        return
    if not allow:
        raise NotPortable(
            "the export would not run on another computer:\n  "
            + "\n  ".join(lines)
            + "\nInstall the real packages here and export again, or pass --allow-standins to"
            " export it as it is"
        )
    warnings.extend(lines)


def copy_launch_tree(path: str, folder: Folder, name: str, *, export_root: str) -> str:
    """Copy the folder of the launch file ``path`` into ``folder``/``name`` (through the export
    folder's checks: nothing planted there is followed); returns the file's name in it.

    ``export_root``, the folder the export writes, is not copied when it lies inside the
    launch file's folder."""
    source = os.path.dirname(os.path.abspath(path))
    skipped = os.path.realpath(export_root)
    total = 0
    tree = folder.subfolder(name, 0o755)
    opened = {source: tree}
    try:
        for here, dirs, files in os.walk(source):
            dest = opened[here]
            dirs[:] = sorted(
                d
                for d in dirs
                if d not in SKIPPED
                and os.path.realpath(os.path.join(here, d)) != skipped
                and not os.path.islink(os.path.join(here, d))
            )
            for d in dirs:
                opened[os.path.join(here, d)] = dest.subfolder(d, 0o755)
            for file in sorted(files):
                full = os.path.join(here, file)
                if not os.path.isfile(full):
                    continue  # a broken link, a socket
                with open(full, "rb") as f:
                    data = f.read()
                total += len(data)
                if total > MAX_TREE_BYTES:
                    raise MlaunchError(
                        f"{source}: the launch file's folder holds more than"
                        f" {MAX_TREE_BYTES // (1024 * 1024)} MiB; an export copies that folder,"
                        " so put the launch file in a folder of its own (with what it includes"
                        " and reads)"
                    )
                dest.write(file, data, 0o755 if os.access(full, os.X_OK) else 0o644)
    finally:
        for opened_folder in opened.values():
            opened_folder.close()
    return os.path.basename(path)


def mlaunch_command(path: str) -> list[str]:
    """The mlaunch a unit runs: ``mlaunch`` on ``path`` (the units' PATH), else this one."""
    found = shutil.which("mlaunch", path=path)
    if found is not None:
        return [os.path.abspath(found)]
    return [sys.executable, "-m", "mlaunch"]


def stem(path: str) -> str:
    """The launch file's name without its suffixes (an export's default name)."""
    name = os.path.basename(path)
    for suffix in (".launch.py", ".launch.yaml", ".launch.xml", ".launch", ".py", ".yaml", ".xml"):
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return name
