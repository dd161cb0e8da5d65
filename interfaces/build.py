"""Builds the ROS 2 interface packages of this folder into wheels, for machines without ROS 2.

PyPI has the rosidl tool chain and most message packages as ``ros-jazzy-*`` wheels, but not
``tf2_msgs`` or ``composition_interfaces``, which the stand-ins need for /tf and for component
containers. ``scripts/setup`` runs this script: it installs the pinned tool chain
(``toolchain.txt``) into a venv of its own, runs CMake + rosidl on each package folder here, and
packs each install tree as a wheel laid out like the ``ros-jazzy-*`` ones (Python package in
site-packages, libraries, headers and the ament index under the venv's prefix).

The wheels are cached under ``$MLAUNCH_INTERFACES_CACHE`` (default ``~/.cache/mlaunch/interfaces``)
in a folder named by a key of the definitions, this script, the tool chain pins and the Python
version, so a second setup builds nothing. Prints the folder holding the wheels on stdout.
Exit status 2 with one clear line when the build cannot run (no compiler, no CMake, no Python
headers), 1 when it ran and failed (the log's tail is shown).
"""

from __future__ import annotations

import argparse
import base64
import csv
import hashlib
import io
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
# Build order; each entry is a folder here with a package.xml and a CMakeLists.txt.
PACKAGES = ("tf2_msgs", "composition_interfaces")
# The wheels' own dependencies: what each package needs at run time, as ros-jazzy-* names.
RUNTIME_REQUIRES = {
    "tf2_msgs": ("ros-jazzy-geometry-msgs", "ros-jazzy-rosidl-default-runtime"),
    "composition_interfaces": ("ros-jazzy-rcl-interfaces", "ros-jazzy-rosidl-default-runtime"),
}
SITE = f"lib/python{sys.version_info.major}.{sys.version_info.minor}/site-packages/"


class BuildError(Exception):
    """The build cannot run or failed; the message is the one line the user sees."""

    def __init__(self, message: str, *, cannot_run: bool = False) -> None:
        super().__init__(message)
        self.cannot_run = cannot_run


def cache_root() -> Path:
    """Where tool chains and wheels are kept between setups (shared by every clone)."""
    explicit = os.environ.get("MLAUNCH_INTERFACES_CACHE")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache")
    return Path(base) / "mlaunch" / "interfaces"


def _digest(parts: list[bytes]) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(len(part).to_bytes(8, "little"))
        h.update(part)
    return h.hexdigest()[:20]


def _interpreter() -> bytes:
    return f"{sys.implementation.cache_tag} {sysconfig.get_platform()}".encode()


def build_key() -> str:
    """The cache key: every file of this folder (definitions, CMake, this script, pins) + Python."""
    parts = [_interpreter()]
    for path in sorted(HERE.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts:
            parts += [path.relative_to(HERE).as_posix().encode(), path.read_bytes()]
    return _digest(parts)


def toolchain_key() -> str:
    """The tool chain venv's key: its pins and the Python it runs on."""
    return _digest([_interpreter(), (HERE / "toolchain.txt").read_bytes()])


def check_tools() -> None:
    """Raises BuildError(cannot_run) naming what is missing to compile a rosidl package."""
    missing = [
        tool
        for tool in ("cmake", os.environ.get("CC", "cc"), os.environ.get("CXX", "c++"))
        if shutil.which(tool) is None
    ]
    include = sysconfig.get_paths()["include"]
    if not Path(include, "Python.h").is_file():
        missing.append(f"Python headers ({include}/Python.h)")
    if missing:
        raise BuildError(
            f"cannot build the ROS interface packages: missing {', '.join(missing)} "
            "(on Debian: apt-get install cmake gcc g++ python3-dev)",
            cannot_run=True,
        )


def _run(argv: list[str], log: Path, env: dict[str, str] | None = None) -> None:
    with log.open("ab") as out:
        out.write(f"$ {' '.join(argv)}\n".encode())
        out.flush()
        done = subprocess.run(argv, stdout=out, stderr=subprocess.STDOUT, env=env, check=False)
    if done.returncode != 0:
        tail = log.read_text(errors="replace").splitlines()[-25:]
        raise BuildError(f"{argv[0]} exited {done.returncode} (log: {log}):\n" + "\n".join(tail))


def toolchain_venv(root: Path) -> Path:
    """The venv holding the pinned rosidl tool chain, made on first use."""
    venv = root / f"toolchain-{toolchain_key()}"
    if (venv / ".complete").is_file():
        return venv
    shutil.rmtree(venv, ignore_errors=True)
    root.mkdir(parents=True, exist_ok=True)
    log = root / "toolchain.log"
    log.write_bytes(b"")
    _run([sys.executable, "-m", "venv", str(venv)], log)
    pip = [str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet"]
    _run([*pip, "--disable-pip-version-check", "-r", str(HERE / "toolchain.txt")], log)
    (venv / ".complete").write_text("")
    return venv


def package_version(name: str) -> str:
    """The <version> of a package.xml here."""
    text = (HERE / name / "package.xml").read_text()
    found = re.search(r"<version>\s*([^<\s]+)\s*</version>", text)
    if found is None:
        raise BuildError(f"{HERE / name / 'package.xml'}: no <version> element")
    return found.group(1)


def build_package(name: str, venv: Path, work: Path) -> Path:
    """Configures, builds and installs one package; returns its install prefix."""
    build, prefix, log = work / "build" / name, work / "stage" / name, work / f"{name}.log"
    env = dict(os.environ)
    # ament finds packages through AMENT_PREFIX_PATH at configure time, not only CMAKE_PREFIX_PATH.
    env["AMENT_PREFIX_PATH"] = env["CMAKE_PREFIX_PATH"] = str(venv)
    env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    env["LD_LIBRARY_PATH"] = f"{venv / 'lib'}{os.pathsep}{env.get('LD_LIBRARY_PATH', '')}"
    env.pop("PYTHONPATH", None)
    configure = [
        "cmake",
        "-S",
        str(HERE / name),
        "-B",
        str(build),
        f"-DCMAKE_INSTALL_PREFIX={prefix}",
        f"-DCMAKE_PROJECT_INCLUDE={HERE / 'drop_missing_includes.cmake'}",
        f"-DPython3_EXECUTABLE={venv / 'bin' / 'python'}",
        "-DCMAKE_BUILD_TYPE=Release",
        "-DBUILD_TESTING=OFF",
    ]
    _run(configure, log, env)
    _run(["cmake", "--build", str(build), "--parallel", str(os.cpu_count() or 2)], log, env)
    _run(["cmake", "--install", str(build)], log, env)
    return prefix


def wheel_tag() -> str:
    """The tag of a wheel with compiled extensions for this interpreter."""
    abi = f"cp{sys.version_info.major}{sys.version_info.minor}"
    return f"{abi}-{abi}-{sysconfig.get_platform().replace('-', '_').replace('.', '_')}"


def _record_line(arcname: str, data: bytes) -> list[str]:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return [arcname, f"sha256={digest}", str(len(data))]


def pack_wheel(name: str, prefix: Path, out: Path) -> Path:
    """Packs an install prefix as a wheel: site-packages at the root, the rest as prefix data."""
    version = package_version(name)
    dist = f"mlaunch_{name}"
    data_dir, info_dir = f"{dist}-{version}.data/data/", f"{dist}-{version}.dist-info/"
    files: list[tuple[str, bytes]] = []
    for path in sorted(prefix.rglob("*")):
        rel = path.relative_to(prefix).as_posix()
        if not path.is_file() or "__pycache__" in rel or ".egg-info/" in rel:
            continue
        arcname = rel[len(SITE) :] if rel.startswith(SITE) else data_dir + rel
        files.append((arcname, path.read_bytes()))
    requires = "".join(f"Requires-Dist: {req}\n" for req in RUNTIME_REQUIRES.get(name, ()))
    metadata = (
        f"Metadata-Version: 2.1\nName: mlaunch-{name.replace('_', '-')}\nVersion: {version}\n"
        f"Summary: ROS 2 {name} interfaces, built by mlaunch's setup with rosidl\n{requires}"
    )
    wheel = (
        f"Wheel-Version: 1.0\nGenerator: mlaunch interfaces/build.py\n"
        f"Root-Is-Purelib: false\nTag: {wheel_tag()}\n"
    )
    files += [
        (info_dir + "METADATA", metadata.encode()),
        (info_dir + "WHEEL", wheel.encode()),
        (info_dir + "top_level.txt", f"{name}\n".encode()),
    ]
    record = io.StringIO()
    writer = csv.writer(record, lineterminator="\n")
    for arcname, data in files:
        writer.writerow(_record_line(arcname, data))
    writer.writerow([info_dir + "RECORD", "", ""])
    target = out / f"{dist}-{version}-{wheel_tag()}.whl"
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as archive:
        for arcname, data in files:
            archive.writestr(arcname, data)
        archive.writestr(info_dir + "RECORD", record.getvalue())
    return target


def build_all(root: Path) -> Path:
    """Returns the folder holding one wheel per package, building it unless it is cached."""
    done = root / f"wheels-{build_key()}"
    if (done / ".complete").is_file():
        return done
    check_tools()
    venv = toolchain_venv(root)
    with tempfile.TemporaryDirectory(prefix="mlaunch-interfaces-") as tmp:
        work = Path(tmp)
        wheels = work / "wheels"
        wheels.mkdir()
        for name in PACKAGES:
            try:
                pack_wheel(name, build_package(name, venv, work), wheels)
            except BuildError as error:
                # The log lives in the temporary folder: keep it where the message says.
                kept = root / f"{name}.log"
                shutil.copyfile(work / f"{name}.log", kept)
                raise BuildError(str(error).replace(str(work / f"{name}.log"), str(kept)))
        (wheels / ".complete").write_text("")
        shutil.rmtree(done, ignore_errors=True)
        shutil.move(str(wheels), done)
    return done


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--key", action="store_true", help="print the cache key and exit")
    args = parser.parse_args(argv)
    if args.key:
        print(build_key())
        return 0
    try:
        print(build_all(cache_root()))
    except BuildError as error:
        print(f"interfaces/build.py: {error}", file=sys.stderr)
        return 2 if error.cannot_run else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
