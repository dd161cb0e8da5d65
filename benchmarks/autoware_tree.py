"""The Autoware fixture: planning_simulator's real launch tree as an ament prefix of stand-ins.

    .venv/bin/python benchmarks/autoware_tree.py [--sources DIR] [--git DIR] [--cache DIR]

Autoware's planning_simulator (autoware_launch 0.43.0 and the packages its launch files read:
autoware.universe and autoware_core of that release, the sample vehicle and sensor kit, the
individual parameters, the sensor component descriptions) is pinned by repository, commit and
content in ``autoware-sources.tsv`` and never copied into this repository. ``scripts/sources.py``
gets the archives: downloaded (``$MLAUNCH_SOURCES_URL``, GitHub by default), taken from a folder
of git clones (``--git DIR``), or read from a folder that already holds them (``--sources DIR``,
checked against the pins like a download). They are kept in ``benchmarks/.cache/autoware``.

The tree is then laid out as an ament prefix, as colcon would install it: each package's folder
(without its C++ sources and tests) as ``share/PACKAGE``, the ament index, ``bin/xacro``, and
for every executable a launch of the tree starts, ``lib/PACKAGE/EXECUTABLE``:

- a recorder (``sh``: says it runs on ``$MLAUNCH_FIXTURE_FIFO`` if set, then sleeps and answers
  nothing), or
- for rclcpp_components' containers, ``autoware_container.py``: mlaunch's container stand-in
  hosting every plugin as a bare node, saying each load on the same FIFO.

Which executables those are is read from the tree itself (``mlaunch --print --format json``), and
the prefix is checked: the tree starts ``PROCESSES`` processes and loads ``COMPOSABLES``
composable nodes, none of them missing. The prefix is built once per sources, builder and
interpreter (``prefix-KEY``). Prints the command that launches the tree.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import tarfile
import tempfile
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
PINS = HERE / "autoware-sources.tsv"
CONTAINER = HERE / "autoware_container.py"
CACHE = HERE / ".cache" / "autoware"
FIFO_VARIABLE = "MLAUNCH_FIXTURE_FIFO"
LAUNCH = ("autoware_launch", "launch/planning_simulator.launch.xml")
PROCESSES = 55  # planning_simulator with rviz, as Autoware 0.43.0 launches it
COMPOSABLES = 53
CONTAINERS = ("component_container", "component_container_mt", "component_container_isolated")
# What a package installs to share/ is its folder; these hold what is compiled, not installed.
NOT_INSTALLED = {"src", "include", "test", "tests", "image", "images", "docs", "doc", "media"}

RECORDER = """\
#!/bin/sh
# A recorder of the Autoware fixture, in place of {what}: says it runs, sleeps, answers nothing.
if [ -n "${{{fifo}:-}}" ]; then exec 3>>"${fifo}"; echo "p {what}" >&3; fi
exec sleep 2147483647
"""

CONTAINER_SHIM = """\
#!/bin/sh
# rclcpp_components' {name} in the Autoware fixture: the container stand-in hosting any plugin.
exec "{python}" "{script}" "$@"
"""


class FixtureError(Exception):
    """Sources that cannot be had, or a tree that is not the size it must be."""


@dataclass(frozen=True)
class Tree:
    """A built fixture: the prefix, and the launch of the tree with its arguments."""

    prefix: Path
    map_path: Path

    @property
    def launch_file(self) -> Path:
        return self.prefix / "share" / LAUNCH[0] / LAUNCH[1]

    @property
    def arguments(self) -> list[str]:
        return [f"map_path:={self.map_path}"]

    def environ(self, base: dict[str, str]) -> dict[str, str]:
        """``base`` with the prefix first on AMENT_PREFIX_PATH and PATH (for xacro)."""
        env = dict(base)
        for name, entry in (("AMENT_PREFIX_PATH", self.prefix), ("PATH", self.prefix / "bin")):
            rest = env.get(name, "")
            env[name] = f"{entry}:{rest}" if rest else str(entry)
        return env


def _sources_module() -> object:
    sys.path.insert(0, str(REPO / "scripts"))
    try:
        import sources
    finally:
        sys.path.pop(0)
    return sources


def get_sources(folder: Path, git: Path | None) -> Path:
    """The pinned archives in ``folder``: kept if there and right, else fetched (or cloned)."""
    sources = _sources_module()
    base = os.environ.get("MLAUNCH_SOURCES_URL") or sources.DEFAULT_URL  # type: ignore[attr-defined]
    try:
        return sources.fetch(PINS, folder, base, git)  # type: ignore[attr-defined,no-any-return]
    except sources.SourcesError as exc:  # type: ignore[attr-defined]
        raise FixtureError(str(exc)) from None


def have_sources(folder: Path) -> bool:
    """Whether ``folder`` holds every pinned archive (not checked: the build checks)."""
    if not PINS.is_file():
        return False
    names = [line.split("\t", 1)[0] for line in PINS.read_text().splitlines()[1:] if line]
    return bool(names) and all((folder / name).is_file() for name in names)


def prefix_key(sources: Path, python: str) -> str:
    digest = hashlib.sha256()
    for path in (sources / "MANIFEST.tsv", Path(__file__), CONTAINER):
        digest.update(path.read_bytes())
    digest.update(python.encode())
    return digest.hexdigest()[:16]


def build(
    sources: Path,
    cache: Path = CACHE,
    python: str = sys.executable,
    size: tuple[int, int] = (PROCESSES, COMPOSABLES),
) -> Tree:
    """The prefix of the tree from the archives in ``sources``, built once per key and checked
    to start ``size`` (processes, composable nodes)."""
    if not (sources / "MANIFEST.tsv").is_file():
        raise FixtureError(f"{sources} holds no MANIFEST.tsv: get the sources first")
    prefix = cache / f"prefix-{prefix_key(sources, python)}"
    tree = Tree(prefix, cache / "map")
    if (prefix / ".built").is_file():
        return tree
    cache.mkdir(parents=True, exist_ok=True)
    _write_map(tree.map_path)
    staging = Path(tempfile.mkdtemp(prefix="staging-", dir=cache))
    try:
        _lay_out(sources, staging, python)
        made = Tree(staging, tree.map_path)
        _add_executables(made, python)
        check(made, python, size)
        (staging / ".built").write_text("")
        for old in cache.glob("prefix-*"):  # of other sources or an older builder
            shutil.rmtree(old)
        staging.rename(prefix)
    finally:
        if staging.exists():
            shutil.rmtree(staging)
    # The prefix's absolute path is in the JSON plan of the check only: nothing to rewrite.
    return tree


def _write_map(folder: Path) -> None:
    """The map folder the tree is given: its files are read by nodes, never by the launch."""
    folder.mkdir(parents=True, exist_ok=True)
    for name in ("lanelet2_map.osm", "pointcloud_map.pcd", "map_projector_info.yaml"):
        path = folder / name
        if not path.exists():
            path.write_text("")


def _lay_out(sources: Path, prefix: Path, python: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        for archive in sorted(sources.glob("*.tar.gz")):
            with tarfile.open(archive) as tar:
                tar.extractall(tmp, filter="data")
        index = prefix / "share" / "ament_index" / "resource_index" / "packages"
        index.mkdir(parents=True)
        for manifest in sorted(Path(tmp).rglob("package.xml")):
            found = re.search(r"<name>\s*([^<\s]+)\s*</name>", manifest.read_text())
            if found is None:
                raise FixtureError(f"{manifest}: no <name>")
            name = found.group(1)
            share = prefix / "share" / name
            if share.exists():
                raise FixtureError(f"two packages named {name!r} in the sources")
            top = manifest.parent
            shutil.copytree(
                top,
                share,
                symlinks=True,
                ignore=lambda d, names, top=top: (
                    [n for n in names if n in NOT_INSTALLED] if Path(d) == top else []
                ),
            )
            (index / name).write_text("")
    (prefix / "bin").mkdir()
    xacro = Path(python).parent / "xacro"
    if not xacro.is_file():
        raise FixtureError(f"no {xacro}: the tree's vehicle description needs xacro")
    os.symlink(xacro, prefix / "bin" / "xacro")


def plan_json(tree: Tree, python: str) -> dict[str, object]:
    """mlaunch's resolved plan of the tree (``--print --format json``)."""
    command = [python, "-m", "mlaunch", "--print", "--format", "json", str(tree.launch_file)]
    done = subprocess.run(
        [*command, *tree.arguments],
        capture_output=True,
        text=True,
        env=tree.environ(dict(os.environ)),
        cwd=REPO,
        check=False,
    )
    if done.returncode != 0:
        raise FixtureError(f"mlaunch cannot resolve the tree: {done.stderr.strip()[-2000:]}")
    plan: dict[str, object] = json.loads(done.stdout)
    return plan


def _nodes(plan: dict[str, object]) -> list[dict[str, object]]:
    steps = plan.get("steps")
    assert isinstance(steps, list)
    return [s["node"] for s in steps if s.get("kind") == "process" and s.get("node")]


def _add_executables(tree: Tree, python: str) -> None:
    index = tree.prefix / "share" / "ament_index" / "resource_index" / "packages"
    for node in _nodes(plan_json(tree, python)):
        package, executable = str(node["package"]), str(node["executable"])
        if not (index / package).exists():  # a ROS 2 package (robot_state_publisher, rviz2...)
            share = tree.prefix / "share" / package
            share.mkdir(parents=True)
            (share / "package.xml").write_text(
                f'<?xml version="1.0"?>\n<package format="3">\n  <name>{package}</name>\n'
                "  <version>0.0.0</version>\n  <description>fixture</description>\n"
                "  <maintainer email='none@example.com'>none</maintainer>\n"
                "  <license>Apache-2.0</license>\n</package>\n"
            )
            (index / package).write_text("")
        path = tree.prefix / "lib" / package / executable
        path.parent.mkdir(parents=True, exist_ok=True)
        if package == "rclcpp_components" and executable in CONTAINERS:
            text = CONTAINER_SHIM.format(name=executable, python=python, script=CONTAINER)
        else:
            text = RECORDER.format(what=f"{package}/{executable}", fifo=FIFO_VARIABLE)
        path.write_text(text)
        path.chmod(path.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)


def check(
    tree: Tree, python: str, size: tuple[int, int] = (PROCESSES, COMPOSABLES)
) -> tuple[int, int]:
    """The tree's size as mlaunch resolves it; a FixtureError if it is not planning_simulator's."""
    plan = plan_json(tree, python)
    warnings = [str(w) for w in plan.get("warnings", []) if "executable" in str(w)]  # type: ignore[attr-defined]
    if warnings:
        raise FixtureError(f"executables missing from the fixture: {warnings[0]}")
    steps = plan.get("steps")
    assert isinstance(steps, list)
    processes = sum(1 for s in steps if s.get("kind") == "process")
    composables = sum(len(s.get("nodes", [])) for s in steps if s.get("kind") == "load_components")
    if (processes, composables) != size:
        raise FixtureError(
            f"the tree resolves to {processes} processes and {composables} composable nodes,"
            f" not planning_simulator's {size[0]} and {size[1]}"
        )
    return processes, composables


def ensure(sources: Path | None = None, git: Path | None = None, cache: Path = CACHE) -> Tree:
    """The built tree: sources fetched (or taken from ``sources``/``git``), prefix built.

    The archives end up in ``cache/sources`` either way, where the benchmark looks for them
    (those of ``sources`` are copied there, then checked against the pins like a download)."""
    folder = cache / "sources"
    if sources is not None and sources.resolve() != folder.resolve():
        folder.mkdir(parents=True, exist_ok=True)
        for archive in sources.glob("*.tar.gz"):
            shutil.copyfile(archive, folder / archive.name)
    return build(get_sources(folder, git), cache)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sources", type=Path, help="a folder holding the pinned archives")
    parser.add_argument("--git", type=Path, help="a folder of git clones to take them from")
    parser.add_argument("--cache", type=Path, default=CACHE, help=f"default: {CACHE}")
    args = parser.parse_args(argv)
    try:
        tree = ensure(args.sources, args.git, args.cache)
    except FixtureError as exc:
        print(f"autoware_tree: {exc}", file=sys.stderr)
        return 1
    env = f"AMENT_PREFIX_PATH={tree.prefix}:$AMENT_PREFIX_PATH PATH={tree.prefix}/bin:$PATH"
    print(f"{env} mlaunch {tree.launch_file} {' '.join(tree.arguments)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
