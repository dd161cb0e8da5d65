"""Packs the pure Python ROS 2 demo packages (demo_nodes_py and lifecycle_py, ament_python) into
one wheel laid out as colcon installs them, for ``scripts/setup --real-nodes``.

Nothing is compiled: the package's own ``setup.py`` is run only to read what it declares
(``setuptools.setup`` is replaced by a recorder), and the wheel holds its Python modules in
site-packages, its ``data_files`` (the ament index marker, ``share/<package>/package.xml``, ...)
under the prefix, and each console script as ``lib/<package>/<name>`` (``setup.cfg``'s
``install_scripts=$base/lib/<package>``, where ``ros2 run`` and launch_ros look). pip writes
no launcher for a prefix data file, so each program starts the Python of the prefix it is in
(``<prefix>/bin/python3``: the venv's) through a two-line /bin/sh preamble that Python reads as
a string.

The source of each is its folder in the archive whose ``MANIFEST.tsv`` row lists it in its
paths (ros2/demos has both beside demo_nodes_cpp). The wheel is cached beside the C++ one
(``build.py``'s cache) under a key of those folders' files, this script, ``build.py`` (its wheel
packer) and the interpreter, so it is packed again only when one of them changes, and a change
here never rebuilds the C++ programs. A package no archive has is left out with a warning.
Prints the wheel's folder; exit status 2 with one line when no archive has any of them.
"""

from __future__ import annotations

import argparse
import csv
import importlib.util
import json
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
PACKAGES, DIST = ("demo_nodes_py", "lifecycle_py"), "mlaunch_real_nodes_py"

# Run in the package's folder by the build's Python: prints what setup.py declares as JSON.
READ_SETUP = """
import json, runpy, setuptools, sys
declared = {}
setuptools.setup = lambda **kwargs: declared.update(kwargs)
runpy.run_path("setup.py", run_name="__main__")
json.dump({key: declared.get(key) for key in ("packages", "data_files", "entry_points")},
          sys.stdout)
"""
# What a console script runs: /bin/sh execs the prefix's Python on this file, which then reads
# the first two lines as one string.
PROGRAM = """#!/bin/sh
'''exec' "$(dirname -- "$0")/../../bin/python3" "$0" "$@"
' '''
# {package}'s console script {name} ({target}), run by the Python of this prefix.
import sys

from {module} import {function}

if __name__ == "__main__":
    sys.exit({function}())
"""


def _load_build():  # type: ignore[no-untyped-def]
    """build.py beside this script: its manifest reader, cache, key helpers and wheel packer."""
    spec = importlib.util.spec_from_file_location("mlaunch_real_nodes_build", HERE / "build.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


build = _load_build()


def find_archive(sources: Path, package: str) -> tuple[str, str, str] | None:
    """The archive whose MANIFEST.tsv paths list the package: its stem, repository, commit."""
    with (sources / "MANIFEST.tsv").open(newline="") as handle:
        for row in csv.DictReader(handle, delimiter="\t"):
            if package in row["paths"].split():
                return row["archive"].removesuffix(".tar.gz"), row["repo"], row["commit"]
    return None


Origin = tuple[str, str, str]  # archive stem, repository, commit


def package_files(sources: Path) -> dict[str, tuple[Origin, dict[str, bytes]]]:
    """Each package some archive has: where it is from (find_archive) and its files (path below
    the package folder -> bytes)."""
    found: dict[str, tuple[Origin, dict[str, bytes]]] = {}
    for package in PACKAGES:
        origin = find_archive(sources, package)
        if origin is not None:
            found[package] = (origin, _files(sources, origin[0], package))
    if not found:
        raise build.BuildError(
            f"no archive of {sources} has {' or '.join(PACKAGES)} (MANIFEST.tsv lists them in no"
            f" row's paths: ros2/demos has them beside demo_nodes_cpp): they are not installed",
            cannot_run=True,
        )
    return found


def _files(sources: Path, stem: str, package: str) -> dict[str, bytes]:
    archive, top = sources / f"{stem}.tar.gz", f"{stem}/{package}/"
    found: dict[str, bytes] = {}
    with tarfile.open(archive) as tar:
        for member in tar:
            if member.isfile() and member.name.startswith(top):
                handle = tar.extractfile(member)
                assert handle is not None
                found[member.name[len(top) :]] = handle.read()
    if "setup.py" not in found:
        raise build.BuildError(f"{archive} has no {top}setup.py", cannot_run=True)
    return found


def build_key(packages: dict[str, tuple[Origin, dict[str, bytes]]]) -> str:
    """The cache key: the packages' files, this script, build.py and the interpreter."""
    parts = [build.ib._interpreter()]
    for path in (Path(__file__).resolve(), HERE / "build.py"):
        parts.append(path.read_bytes())
    for package, (_, files) in sorted(packages.items()):
        parts.append(package.encode())
        for name in sorted(files):
            parts += [name.encode(), files[name]]
    return str(build.ib._digest(parts))


def declared(source: Path) -> dict[str, object]:
    """What the package's setup.py passes to setuptools.setup (packages, data, scripts)."""
    done = subprocess.run(
        [sys.executable, "-c", READ_SETUP], cwd=source, capture_output=True, text=True, check=False
    )
    if done.returncode != 0:
        raise build.BuildError(f"{source / 'setup.py'} did not run: {done.stderr.strip()[-500:]}")
    result: dict[str, object] = json.loads(done.stdout)
    return result


def install_tree(source: Path, prefix: Path, package_name: str) -> None:
    """Lays the package out in prefix as colcon's ament_python build installs it."""
    setup = declared(source)
    site = prefix / build.SITE
    for package in setup["packages"] or []:  # type: ignore[attr-defined]
        folder = source / package.replace(".", "/")
        for path in folder.iterdir():
            if path.is_file() and path.suffix == ".py":
                (site / folder.relative_to(source)).mkdir(parents=True, exist_ok=True)
                shutil.copyfile(path, site / path.relative_to(source))
    for target, names in setup["data_files"] or []:  # type: ignore[attr-defined]
        (prefix / target).mkdir(parents=True, exist_ok=True)
        for name in names:
            shutil.copyfile(source / name, prefix / target / Path(name).name)
    scripts = (setup["entry_points"] or {}).get("console_scripts", [])  # type: ignore[attr-defined]
    lib = prefix / "lib" / package_name
    lib.mkdir(parents=True, exist_ok=True)
    for line in scripts:
        name, target = (part.strip() for part in line.split("=", 1))
        module, function = target.split(":")
        program = lib / name
        program.write_text(
            PROGRAM.format(
                package=package_name, name=name, target=target, module=module, function=function
            )
        )
        program.chmod(0o755)


def build_all(sources: Path, root: Path) -> Path:
    """Returns the folder holding the wheel, packing it unless it is cached."""
    packages = package_files(sources)
    for missing in sorted(set(PACKAGES) - set(packages)):
        print(
            f"python_packages.py: warning: no archive of {sources} has {missing}", file=sys.stderr
        )
    done = root / f"python-{build_key(packages)}"
    if (done / ".complete").is_file():
        return done
    with tempfile.TemporaryDirectory(prefix="mlaunch-real-nodes-py-") as tmp:
        prefix, wheels = Path(tmp) / "install", Path(tmp) / "wheel"
        origins: dict[str, tuple[str, str]] = {}
        for package, ((stem, repo, commit), files) in sorted(packages.items()):
            source = Path(tmp) / "src" / package
            for name, data in files.items():
                (source / name).parent.mkdir(parents=True, exist_ok=True)
                (source / name).write_bytes(data)
            install_tree(source, prefix, package)
            origins[stem] = (repo, commit)
        wheels.mkdir()
        names = ", ".join(sorted(packages))
        build.pack_wheel(prefix, wheels, origins, dist=DIST, names=names)
        return Path(build.publish(wheels, done))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    build.add_sources_argument(parser)
    parser.add_argument("--key", action="store_true", help="print the cache key and exit")
    args = parser.parse_args(argv)
    sources = args.sources.resolve()
    try:
        if args.key:
            print(build_key(package_files(sources)))
        else:
            print(build_all(sources, build.cache_root()))
    except (build.BuildError, OSError, tarfile.TarError) as error:
        print(f"scripts/real_nodes/python_packages.py: {error}", file=sys.stderr)
        return 2 if getattr(error, "cannot_run", True) else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
