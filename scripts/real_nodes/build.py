"""Builds real ROS 2 Jazzy C++ programs (rclcpp, the component container, tf2_ros,
robot_state_publisher, the demo talker/listener) into one wheel, for machines without ROS 2.

PyPI's ros-jazzy-* wheels ship rcl, rmw, rcutils, rosidl and ament_cmake with their CMake
configs, but no rclcpp and nothing built on it. ``scripts/setup --real-nodes [DIR]`` runs this
script on a folder of upstream source archives (``DIR/MANIFEST.tsv`` names them: the archive,
its repository and commit, the package folders in it); it makes a venv with the pinned
libraries to compile against (``toolchain.txt`` here, on top of ``interfaces/toolchain.txt``
and the project's own composition_interfaces wheel), unpacks the archives into a temporary
folder (never into DIR, which may be read-only), configures, builds and installs each package
in dependency order into one prefix with CMake (at most 2 jobs), and packs that prefix as one
wheel laid out like the ros-jazzy-* ones: installed, the programs are under the venv's prefix
(``lib/<package>/<program>``, ``share/ament_index``), where mlaunch finds installed packages.

The wheel is cached under ``~/.cache/mlaunch/real-nodes`` (``$MLAUNCH_REAL_NODES_CACHE``) in a
folder named by a key of the archives, this folder, the pins, the interface wheels, the compiler
and CMake, so a second setup builds nothing. Prints that folder on stdout. Exit status 2 with
one line when the build cannot run, 1 when it ran and failed (the log's tail is shown).

Workarounds, each needed with the wheels of late 2025 (see the comments where each is done):
libpython at link time, bad link items in the wheels' CMake exports (``project_hook.cmake``),
Debian packages in place of the vendor packages (``vendor/``), our own CMakeLists for the two
demo packages (``cmake_lists/``), and mode bits in the wheel.
"""

from __future__ import annotations

import argparse
import csv
import importlib.util
import io
import os
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import tempfile
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
DEFAULT_SOURCES = ROOT.parent / "shared" / "ros2-src"
VERSION = "0.1.0"
DIST = "mlaunch_real_nodes"

# Build order: (archive stem, folder in it, package). "vendor/..." are folders here.
PACKAGES: tuple[tuple[str, str, str], ...] = (
    ("vendor", "console_bridge_vendor", "console_bridge_vendor"),
    ("vendor", "tinyxml2_vendor", "tinyxml2_vendor"),
    ("vendor", "orocos_kdl_vendor", "orocos_kdl_vendor"),
    ("rcl_interfaces", "statistics_msgs", "statistics_msgs"),
    ("libstatistics_collector", ".", "libstatistics_collector"),
    # The full tf2_msgs: tf2_ros needs its LookupTransform action, which interfaces/tf2_msgs
    # lacks; installed, it replaces the project's tf2_msgs wheel (scripts/setup says so).
    ("geometry2", "tf2_msgs", "tf2_msgs"),
    ("rclcpp", "rclcpp", "rclcpp"),
    ("class_loader", ".", "class_loader"),
    ("pluginlib", "pluginlib", "pluginlib"),
    ("rclcpp", "rclcpp_components", "rclcpp_components"),
    ("rclcpp", "rclcpp_action", "rclcpp_action"),
    ("rclcpp", "rclcpp_lifecycle", "rclcpp_lifecycle"),
    ("urdf_parser_plugin", ".", "urdf_parser_plugin"),
    ("urdf", ".", "urdf"),
    ("kdl_parser", "kdl_parser", "kdl_parser"),
    ("message_filters", ".", "message_filters"),
    ("geometry2", "tf2", "tf2"),
    ("geometry2", "tf2_ros", "tf2_ros"),
    ("robot_state_publisher", ".", "robot_state_publisher"),
    ("demos", "demo_nodes_cpp", "demo_nodes_cpp"),
    ("demos", "composition", "composition"),
    # The lifecycle demo (lifecycle_talker, _listener, _service_client), upstream CMakeLists as is:
    # three programs on rclcpp_lifecycle and the wheels' lifecycle_msgs.
    ("demos", "lifecycle", "lifecycle"),
)
NOT_BUILT = ("install", "python_packages.py")
JOBS = 2  # the machines this runs on share 2 cores between several builds and test runs
SITE = f"lib/python{sys.version_info.major}.{sys.version_info.minor}/site-packages/"
# Debian's libpython (package libpython3.X): see _cmake_arguments.
LIBPYTHON = Path(
    f"/usr/lib/{sysconfig.get_config_var('MULTIARCH') or 'x86_64-linux-gnu'}"
    f"/libpython{sys.version_info.major}.{sys.version_info.minor}.so.1.0"
)


def _load_interfaces_build():  # type: ignore[no-untyped-def]
    """interfaces/build.py, for its cache, key, run and wheel helpers (one copy of each)."""
    spec = importlib.util.spec_from_file_location(
        "mlaunch_interfaces_build", ROOT / "interfaces" / "build.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


ib = _load_interfaces_build()
BuildError = ib.BuildError


def cache_root() -> Path:
    """Where the tool chain venv and the wheel are kept between setups."""
    explicit = os.environ.get("MLAUNCH_REAL_NODES_CACHE")
    if explicit:
        return Path(explicit)
    return ib.cache_root().parent / "real-nodes"


def read_manifest(sources: Path) -> dict[str, tuple[str, str]]:
    """MANIFEST.tsv: archive stem -> (repository, commit)."""
    manifest = sources / "MANIFEST.tsv"
    if not manifest.is_file():
        raise BuildError(
            f"no {manifest}: the folder of ROS 2 source archives must have one", cannot_run=True
        )
    with manifest.open(newline="") as handle:
        rows = list(csv.DictReader(handle, delimiter="\t"))
    found = {row["archive"].removesuffix(".tar.gz"): (row["repo"], row["commit"]) for row in rows}
    missing = sorted({stem for stem, _, _ in PACKAGES if stem != "vendor"} - set(found))
    if missing:
        raise BuildError(f"{manifest} lacks {', '.join(missing)}", cannot_run=True)
    return found


def _tool_versions() -> bytes:
    out = []
    for argv in (["cmake", "--version"], [os.environ.get("CXX", "c++"), "--version"]):
        done = subprocess.run(argv, capture_output=True, check=False)
        out.append(done.stdout.split(b"\n", 1)[0])
    return b"\n".join(out)


def build_key(sources: Path, interfaces: Path) -> str:
    """The cache key: the archives built from, every file here, the pins, the interface wheels,
    the tools. Other archives of the folder (a pure Python package's: python_packages.py) are
    not in it, so adding one rebuilds nothing here."""
    parts = [ib._interpreter(), _tool_versions(), str(LIBPYTHON).encode()]
    read_manifest(sources)  # names the archives that are missing
    for stem in sorted({stem for stem, _, _ in PACKAGES if stem != "vendor"}):
        parts += [stem.encode(), (sources / f"{stem}.tar.gz").read_bytes()]
    shared = [
        ROOT / "interfaces" / "toolchain.txt",
        ROOT / "interfaces" / "drop_missing_includes.cmake",
    ]
    for path in [*sorted(HERE.rglob("*")), *shared]:
        # `install` (setup's side: Debian packages, pip) does not change what is built, nor does
        # python_packages.py (the pure Python packages: a wheel with its own key).
        if path.is_file() and "__pycache__" not in path.parts and path.name not in NOT_BUILT:
            parts += [path.relative_to(ROOT).as_posix().encode(), path.read_bytes()]
    parts.append(interfaces.resolve().name.encode())  # wheels-KEY: the interfaces' own key
    return ib._digest(parts)


def check_tools() -> None:
    """BuildError(cannot_run) naming what is missing to compile the programs."""
    ib.check_tools()
    wanted = {
        "libpython3": LIBPYTHON,
        "libconsole-bridge-dev": Path("/usr/include/console_bridge"),
        "liburdfdom-dev": Path("/usr/include/urdf_parser"),
        "liburdfdom-headers-dev": Path("/usr/include/urdf_model"),
        "liborocos-kdl-dev": Path("/usr/include/kdl"),
        "libtinyxml2-dev": Path("/usr/include/tinyxml2.h"),
        "libeigen3-dev": Path("/usr/include/eigen3"),
    }
    missing = [name for name, path in wanted.items() if not path.exists()]
    if missing:
        names = " ".join(
            name if name != "libpython3" else LIBPYTHON.name.split(".so")[0] for name in missing
        )
        raise BuildError(
            f"cannot build the real ROS 2 nodes: missing Debian packages (apt-get install {names})",
            cannot_run=True,
        )


def toolchain_venv(root: Path, interfaces: Path) -> Path:
    """The venv with the pinned libraries and tools to build against, made on first use."""
    pins = (ROOT / "interfaces" / "toolchain.txt").read_bytes() + (
        HERE / "toolchain.txt"
    ).read_bytes()
    wheels = sorted(interfaces.glob("mlaunch_composition_interfaces-*.whl"))
    if not wheels:
        raise BuildError(f"no composition_interfaces wheel in {interfaces}", cannot_run=True)
    venv = (
        root
        / f"toolchain-{ib._digest([ib._interpreter(), pins, interfaces.resolve().name.encode()])}"
    )
    if (venv / ".complete").is_file():
        return venv
    shutil.rmtree(venv, ignore_errors=True)
    root.mkdir(parents=True, exist_ok=True)
    log = root / "toolchain.log"
    log.write_bytes(b"")
    ib._run([sys.executable, "-m", "venv", str(venv)], log)
    pip = [
        str(venv / "bin" / "python"),
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
    ]
    ib._run(
        [*pip, "-r", str(ROOT / "interfaces" / "toolchain.txt"), "-r", str(HERE / "toolchain.txt")],
        log,
    )
    ib._run([*pip, "--no-deps", str(wheels[0])], log)
    (venv / ".complete").write_text("")
    return venv


def unpack(sources: Path, work: Path) -> Path:
    """Unpacks every archive into work/src (each has one top folder named like it)."""
    src = work / "src"
    if src.is_dir():  # a kept work folder (--work): unpacked already
        return src
    src.mkdir()
    for stem in sorted({stem for stem, _, _ in PACKAGES if stem != "vendor"}):
        with tarfile.open(sources / f"{stem}.tar.gz") as archive:
            archive.extractall(src, filter="data")
    # Our own CMakeLists for the two demo packages (see the comment at the top of each).
    for folder in (HERE / "cmake_lists").iterdir():
        shutil.copyfile(folder / "CMakeLists.txt", src / "demos" / folder.name / "CMakeLists.txt")
    return src


def build_env(venv: Path, prefix: Path) -> dict[str, str]:
    """The environment of CMake and of the compiler: the prefix being filled, then the venv."""
    env = dict(os.environ)
    site = venv / SITE
    env["AMENT_PREFIX_PATH"] = env["CMAKE_PREFIX_PATH"] = f"{prefix}{os.pathsep}{venv}"
    env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    # The wheels' libraries carry an RPATH that fits only inside site-packages: linking (and the
    # generators that run a freshly built program) need every folder that holds them, which is
    # what the wheels' .pth bootstrap sets for a Python process.
    libs = [prefix / "lib", venv / "lib", *sorted(site.glob("ros_*.libs"))]
    env["LD_LIBRARY_PATH"] = os.pathsep.join(map(str, libs))
    env["PYTHONPATH"] = str(prefix / SITE)  # the messages built here, for the next generators
    return env


def _cmake_arguments(venv: Path, prefix: Path) -> list[str]:
    return [
        f"-DCMAKE_INSTALL_PREFIX={prefix}",
        f"-DCMAKE_PROJECT_INCLUDE={HERE / 'project_hook.cmake'}",
        f"-DPython3_EXECUTABLE={venv / 'bin' / 'python'}",
        "-DCMAKE_BUILD_TYPE=Release",
        "-DBUILD_TESTING=OFF",
        # librcl (and rcl_action, rcl_lifecycle) of the wheels list the Python-generated message
        # libraries as needed, and those leave Py* symbols to the interpreter: manylinux wheels
        # do not link libpython. An executable must resolve every symbol of what it needs, so
        # each one is linked with Debian's libpython (kept with --no-as-needed); shared
        # libraries may leave symbols open, and --as-needed keeps them from recording it.
        f"-DCMAKE_EXE_LINKER_FLAGS=-Wl,--no-as-needed {LIBPYTHON}",
        "-DCMAKE_SHARED_LINKER_FLAGS=-Wl,--as-needed",
    ]


def build_package(source: Path, name: str, venv: Path, prefix: Path, work: Path) -> None:
    """Configures, builds and installs one package into prefix; the log is work/NAME.log."""
    build, log = work / "build" / name, work / f"{name}.log"
    if (build / ".mlaunch-installed").is_file():  # a kept work folder (--work): done already
        return
    env = build_env(venv, prefix)
    ib._run(
        ["cmake", "-S", str(source), "-B", str(build), *_cmake_arguments(venv, prefix)], log, env
    )
    ib._run(["cmake", "--build", str(build), "--parallel", str(JOBS)], log, env)
    ib._run(["cmake", "--install", str(build)], log, env)
    (build / ".mlaunch-installed").write_text("")


def pack_wheel(
    prefix: Path,
    out: Path,
    manifest: dict[str, tuple[str, str]],
    *,
    dist: str = DIST,
    names: str = ", ".join(name for _, _, name in PACKAGES),
) -> Path:
    """Packs the install prefix as one wheel: site-packages at the root, the rest as data.

    Each entry keeps its file's mode bits: without them pip installs the programs as 0644
    and running one is "Permission denied". ``dist`` and ``names`` (the ROS packages in it)
    name the wheel; ``manifest`` gives the repositories and commits it was built from.
    """
    info_dir, data_dir = f"{dist}-{VERSION}.dist-info/", f"{dist}-{VERSION}.data/data/"
    entries: list[tuple[str, bytes, int]] = []
    for path in sorted(prefix.rglob("*")):
        rel = path.relative_to(prefix).as_posix()
        if not path.is_file() or "__pycache__" in rel or ".egg-info/" in rel:
            continue
        arcname = rel[len(SITE) :] if rel.startswith(SITE) else data_dir + rel
        entries.append((arcname, path.read_bytes(), path.stat().st_mode & 0o777))
    sources = "".join(
        f"Source: {repo} {commit}\n" for repo, commit in sorted(set(manifest.values()))
    )
    metadata = (
        f"Metadata-Version: 2.1\nName: {dist.replace('_', '-')}\nVersion: {VERSION}\n"
        f"Summary: ROS 2 Jazzy packages built by mlaunch's setup: {names}\n"
        "Requires-Dist: ros-jazzy-rclpy\nRequires-Dist: ros-jazzy-rcl-action\n"
        f"Requires-Dist: ros-jazzy-rcl-lifecycle\n{sources}"
    )
    wheel = (
        "Wheel-Version: 1.0\nGenerator: mlaunch scripts/real_nodes/build.py\n"
        f"Root-Is-Purelib: false\nTag: {ib.wheel_tag()}\n"
    )
    entries += [
        (info_dir + "METADATA", metadata.encode(), 0o644),
        (info_dir + "WHEEL", wheel.encode(), 0o644),
    ]
    record = io.StringIO()
    writer = csv.writer(record, lineterminator="\n")
    for arcname, data, _ in entries:
        writer.writerow(ib._record_line(arcname, data))
    writer.writerow([info_dir + "RECORD", "", ""])
    entries.append((info_dir + "RECORD", record.getvalue().encode(), 0o644))
    target = out / f"{dist}-{VERSION}-{ib.wheel_tag()}.whl"
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as archive:
        for arcname, data, mode in entries:
            info = zipfile.ZipInfo(arcname, date_time=(2024, 1, 1, 0, 0, 0))
            info.external_attr = (0o100000 | mode) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, data)
    return target


def build_all(sources: Path, interfaces: Path, root: Path, keep: Path | None = None) -> Path:
    """Returns the folder holding the wheel, building it unless it is cached.

    ``keep``: a work folder to build in and keep (to resume after a failure while changing
    this build); by default a temporary one.
    """
    done = root / f"wheel-{build_key(sources, interfaces)}"
    if (done / ".complete").is_file():
        return done
    check_tools()
    manifest = read_manifest(sources)
    venv = toolchain_venv(root, interfaces)
    with tempfile.TemporaryDirectory(prefix="mlaunch-real-nodes-") as tmp:
        work = keep or Path(tmp)
        src, prefix, wheels = unpack(sources, work), work / "install", work / "wheel"
        shutil.rmtree(wheels, ignore_errors=True)
        wheels.mkdir()
        for stem, folder, name in PACKAGES:
            source = HERE / stem / folder if stem == "vendor" else src / stem / folder
            try:
                build_package(source, name, venv, prefix, work)
            except BuildError as error:
                kept = root / f"{name}.log"  # the log lives in the temporary folder
                shutil.copyfile(work / f"{name}.log", kept)
                raise BuildError(str(error).replace(str(work / f"{name}.log"), str(kept)))
            print(f"real-nodes: built {name}", file=sys.stderr, flush=True)
        pack_wheel(prefix, wheels, manifest)
        return publish(wheels, done)


def publish(wheels: Path, done: Path) -> Path:
    """Marks a folder of packed wheels complete and moves it to its place in the cache."""
    (wheels / ".complete").write_text("")
    shutil.rmtree(done, ignore_errors=True)
    done.parent.mkdir(parents=True, exist_ok=True)
    shutil.move(str(wheels), done)
    return done


def add_sources_argument(parser: argparse.ArgumentParser) -> None:
    """The folder of source archives, as each script here takes it."""
    parser.add_argument(
        "sources",
        nargs="?",
        type=Path,
        default=DEFAULT_SOURCES,
        help="the folder of source archives with MANIFEST.tsv",
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_sources_argument(parser)
    parser.add_argument(
        "--interfaces",
        type=Path,
        required=True,
        help="the folder of the interface wheels (interfaces/build.py)",
    )
    parser.add_argument("--key", action="store_true", help="print the cache key and exit")
    parser.add_argument("--work", type=Path, help="build in this folder and keep it (to resume)")
    args = parser.parse_args(argv)
    try:
        if args.key:
            print(build_key(args.sources.resolve(), args.interfaces))
        else:
            print(build_all(args.sources.resolve(), args.interfaces, cache_root(), args.work))
    except (BuildError, OSError) as error:
        print(f"scripts/real_nodes/build.py: {error}", file=sys.stderr)
        return 2 if getattr(error, "cannot_run", True) else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
