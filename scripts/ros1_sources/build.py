"""Makes ROS 1 packages Debian does not ship runnable under Debian's ROS 1, from source archives.

``scripts/setup --ros1-sources DIR`` (or ``MLAUNCH_ROS1_SOURCES=DIR``) runs this script on a
folder of upstream source archives named by ``DIR/MANIFEST.tsv`` (archive, repository, ref,
commit, paths, sha256). Today that is ``arbotix_ros`` (ROS 1 Noetic's ArbotiX driver, which the
smartcar seed runs in simulation): ``arbotix_python`` is pure Python and ``arbotix_msgs`` needs its
messages generated with genpy. Its ``follow_controller`` imports control_msgs's
FollowJointTrajectory action, which Debian does not package either: ``control_msgs/`` here holds
those definitions (the same fields, so the same checksums) and genpy generates them too.

The result is laid out as a catkin install space (``.catkin``, ``lib/PKG/`` for the programs,
``lib/python3/dist-packages`` for the Python packages, ``share/PKG/package.xml``), so rospack
(``ROS_PACKAGE_PATH``) and roslaunch's catkin_find (``CMAKE_PREFIX_PATH``) find it, with a
``setup.sh`` that puts it on those paths and ``PYTHONPATH``, as a workspace's setup does. Each
package imports under ``/usr/bin/python3`` before it is published.

Cached under ``~/.cache/mlaunch/ros1`` (``$MLAUNCH_ROS1_CACHE``) by a key of the archives, the
files here and the generators, so a second setup builds nothing. Prints the prefix on stdout.
Exit status 2 with one clear line when it cannot run (no manifest, a checksum that differs, a
Debian package missing), 1 when a step failed.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
SYSTEM_PYTHON = "/usr/bin/python3"
GENMSG = "/usr/lib/genpy/genmsg_py.py"
GENSRV = "/usr/lib/genpy/gensrv_py.py"
GENACTION = "/usr/lib/actionlib_msgs/genaction.py"
SHARE = Path("/usr/share")
DIST = "lib/python3/dist-packages"
ARCHIVE = "arbotix_ros.tar.gz"
# Message packages the generated ones include, and the Debian packages of their definitions.
DEFINITIONS = {
    "std_msgs": "ros-std-msgs",
    "actionlib_msgs": "ros-actionlib-msgs",
    "trajectory_msgs": "ros-trajectory-msgs",
    "geometry_msgs": "ros-geometry-msgs",
}
# What arbotix_python imports at run time (module -> Debian package).
RUNTIME = {
    "rospy": "python3-rospy",
    "serial": "python3-serial",
    "actionlib": "python3-actionlib",
    "tf.broadcaster": "python3-tf",
    "geometry_msgs.msg": "python3-geometry-msgs",
    "nav_msgs.msg": "python3-nav-msgs",
    "sensor_msgs.msg": "python3-sensor-msgs",
    "diagnostic_msgs.msg": "python3-diagnostic-msgs",
    "trajectory_msgs.msg": "python3-trajectory-msgs",
    "std_srvs.srv": "python3-std-srvs",
    "actionlib_msgs.msg": "python3-actionlib-msgs",
    "genpy": "python3-genpy",
}
# The modules a built prefix must import (under the system's Python) before it is published.
CHECKED = (
    "arbotix_msgs.msg",
    "arbotix_msgs.srv",
    "control_msgs.msg",
    "arbotix_python.arbotix",
    "arbotix_python.diff_controller",
    "arbotix_python.follow_controller",
    "arbotix_python.servo_controller",
    "arbotix_python.linear_controller",
    "arbotix_python.publishers",
    "arbotix_python.io",
)


class BuildError(Exception):
    """The build cannot run or failed; the message is the one line the user sees."""

    def __init__(self, message: str, *, cannot_run: bool = False) -> None:
        super().__init__(message)
        self.cannot_run = cannot_run


def cache_root() -> Path:
    explicit = os.environ.get("MLAUNCH_ROS1_CACHE")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache")
    return Path(base) / "mlaunch" / "ros1"


def read_manifest(sources: Path) -> dict[str, dict[str, str]]:
    """MANIFEST.tsv: archive -> its row; the archive must be there with the pinned checksum."""
    manifest = sources / "MANIFEST.tsv"
    if not manifest.is_file():
        raise BuildError(
            f"no {manifest}: give the folder of ROS 1 source archives"
            " (scripts/setup --ros1-sources DIR)",
            cannot_run=True,
        )
    with manifest.open(newline="") as handle:
        rows = {row["archive"]: row for row in csv.DictReader(handle, delimiter="\t")}
    if ARCHIVE not in rows:
        raise BuildError(f"{manifest} lacks {ARCHIVE}", cannot_run=True)
    path = sources / ARCHIVE
    if not path.is_file():
        raise BuildError(f"{manifest} names {ARCHIVE}, which is not in {sources}", cannot_run=True)
    found = hashlib.sha256(path.read_bytes()).hexdigest()
    want = rows[ARCHIVE].get("sha256", "")
    if found != want:
        raise BuildError(
            f"{path} has sha256 {found}, {manifest} pins {want!r}: not the pinned sources",
            cannot_run=True,
        )
    return rows


def missing_debian_packages() -> list[str]:
    """The Debian packages the build or arbotix_python's imports need that are not installed."""
    if not os.access(SYSTEM_PYTHON, os.X_OK):
        return ["python3"]
    out = [deb for name, deb in DEFINITIONS.items() if not (SHARE / name / "msg").is_dir()]
    if not os.path.isfile(GENMSG):
        out.append("python3-genpy")
    if not os.path.isfile(GENACTION):
        out.append("python3-actionlib-msgs")
    probe = (
        "import importlib, sys\n"
        "for name in sys.argv[1:]:\n"
        "    try:\n        importlib.import_module(name)\n"
        "    except ImportError:\n        print(name)\n"
    )
    done = subprocess.run(
        [SYSTEM_PYTHON, "-c", probe, *RUNTIME],
        capture_output=True,
        text=True,
        check=False,
        env=system_env(),
    )
    out += [RUNTIME[name] for name in done.stdout.split()]
    return sorted(set(out))


def system_env(pythonpath: str | None = None) -> dict[str, str]:
    """The system Python's environment: no virtual environment's packages on its path."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.pop("VIRTUAL_ENV", None)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    return env


def build_key(sources: Path) -> str:
    """The archives, every file here and the generators' versions."""
    read_manifest(sources)
    h = hashlib.sha256()
    parts = [(sources / ARCHIVE).read_bytes()]
    for path in sorted(HERE.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts:
            parts += [path.relative_to(HERE).as_posix().encode(), path.read_bytes()]
    for tool in (GENMSG, GENSRV, GENACTION):
        parts.append(Path(tool).read_bytes() if os.path.isfile(tool) else b"")
    for part in parts:
        h.update(len(part).to_bytes(8, "little"))
        h.update(part)
    return h.hexdigest()[:16]


def run(argv: list[str], what: str) -> None:
    done = subprocess.run(argv, capture_output=True, text=True, check=False, env=system_env())
    if done.returncode != 0:
        tail = (done.stderr or done.stdout).strip().splitlines()[-3:]
        raise BuildError(f"{what} failed (status {done.returncode}): {' | '.join(tail)}")


def includes(own: str, folders: list[Path]) -> list[str]:
    out = [f"-I{own}:{folder}" for folder in folders]
    for name in DEFINITIONS:
        out.append(f"-I{name}:{SHARE / name / 'msg'}")
    return out


def generate(package: str, msgs: list[Path], srvs: list[Path], out: Path) -> None:
    """genpy's Python modules of a package's messages and services, with their __init__s."""
    folders = sorted({p.parent for p in msgs})
    target = out / package
    for kind, files, tool in (("msg", msgs, GENMSG), ("srv", srvs, GENSRV)):
        if not files:
            continue
        dest = target / kind
        for path in files:
            argv = [SYSTEM_PYTHON, tool, "-p", package, "-o", str(dest)]
            run([*argv, *includes(package, folders), str(path)], f"genpy on {path.name}")
        run(
            [SYSTEM_PYTHON, tool, "--initpy", "-p", package, "-o", str(dest)],
            f"genpy's {package}.{kind}",
        )
    (target / "__init__.py").touch()


def lay_out(src: Path, prefix: Path, work: Path) -> None:
    """The catkin install space of arbotix_python, arbotix_msgs and control_msgs."""
    dist = prefix / DIST
    dist.mkdir(parents=True)
    (prefix / ".catkin").write_text("")
    python = src / "arbotix_python"
    share = prefix / "share" / "arbotix_python"
    share.mkdir(parents=True)
    shutil.copy2(python / "package.xml", share)
    shutil.copytree(python / "demos", share / "demos")
    programs = prefix / "lib" / "arbotix_python"
    programs.mkdir(parents=True)
    for program in sorted((python / "bin").iterdir()):
        shutil.copy2(program, programs / program.name)
        (programs / program.name).chmod(0o755)
    shutil.copytree(python / "src" / "arbotix_python", dist / "arbotix_python")

    msgs = src / "arbotix_msgs"
    share = prefix / "share" / "arbotix_msgs"
    share.mkdir(parents=True)
    for part in ("package.xml", "msg", "srv"):
        copy = shutil.copytree if (msgs / part).is_dir() else shutil.copy2
        copy(msgs / part, share / part)
    generate(
        "arbotix_msgs",
        sorted((msgs / "msg").glob("*.msg")),
        sorted((msgs / "srv").glob("*.srv")),
        dist,
    )

    control = HERE / "control_msgs"
    share = prefix / "share" / "control_msgs"
    shutil.copytree(control, share)
    expanded = work / "control_msgs_msg"
    for action in sorted((control / "action").glob("*.action")):
        run(
            [SYSTEM_PYTHON, GENACTION, str(action), "-o", str(expanded)],
            f"genaction on {action.name}",
        )
    if not any(expanded.glob("*.msg")):
        raise BuildError(f"genaction wrote no messages for {control / 'action'}")
    shutil.copytree(expanded, share / "msg", dirs_exist_ok=True)
    generate("control_msgs", sorted((share / "msg").glob("*.msg")), [], dist)
    (prefix / "setup.sh").write_text(SETUP_SH.replace("@PREFIX@", str(prefix)))


SETUP_SH = """\
# A ROS 1 shell for mlaunch's ROS 1 packages built from sources (arbotix_python, arbotix_msgs,
# control_msgs): source it as a catkin workspace's setup.sh. It sets what a ROS 1 setup sets
# (ROS_VERSION, and ROS_DISTRO and ROS_MASTER_URI when unset) and puts this prefix on the paths
# rospack, catkin_find and Python read.
_mlaunch_ros1=@PREFIX@
export ROS_VERSION=1
export ROS_DISTRO="${ROS_DISTRO:-noetic}"
export ROS_MASTER_URI="${ROS_MASTER_URI:-http://localhost:11311}"
case ":${CMAKE_PREFIX_PATH:-}:" in *":$_mlaunch_ros1:"*) ;; *)
    export CMAKE_PREFIX_PATH="$_mlaunch_ros1${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}" ;; esac
case ":${ROS_PACKAGE_PATH:-}:" in *":$_mlaunch_ros1/share:"*) ;; *)
    export ROS_PACKAGE_PATH="$_mlaunch_ros1/share${ROS_PACKAGE_PATH:+:$ROS_PACKAGE_PATH}" ;; esac
case ":${PYTHONPATH:-}:" in *":$_mlaunch_ros1/lib/python3/dist-packages:"*) ;; *)
    export PYTHONPATH="$_mlaunch_ros1/lib/python3/dist-packages${PYTHONPATH:+:$PYTHONPATH}" ;; esac
unset _mlaunch_ros1
"""


def check(prefix: Path) -> None:
    """Every module imports under the system's Python (what a node will run)."""
    probe = "import importlib, sys\nfor name in sys.argv[1:]:\n    importlib.import_module(name)\n"
    done = subprocess.run(
        [SYSTEM_PYTHON, "-c", probe, *CHECKED],
        capture_output=True,
        text=True,
        check=False,
        env=system_env(str(prefix / DIST)),
    )
    if done.returncode != 0:
        tail = done.stderr.strip().splitlines()[-1:]
        raise BuildError(f"the built packages do not import under {SYSTEM_PYTHON}: {tail}")


def unpack(archive: Path, into: Path) -> Path:
    with tarfile.open(archive) as tar:
        tar.extractall(into, filter="data")
    return into / "arbotix_ros"


def build(sources: Path, root: Path) -> Path:
    """The prefix, built unless it is cached."""
    done = root / f"prefix-{build_key(sources)}"
    if (done / ".complete").is_file():
        return done
    missing = missing_debian_packages()
    if missing:
        raise BuildError(
            f"needs Debian packages: apt-get install {' '.join(missing)}", cannot_run=True
        )
    root.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="mlaunch-ros1-", dir=root) as tmp:
        work = Path(tmp)
        # Built where it will live: setup.sh names its own folder.
        staging = work / "prefix"
        src = unpack(sources / ARCHIVE, work / "src")
        lay_out(src, staging, work)
        check(staging)
        shutil.rmtree(done, ignore_errors=True)
        shutil.move(str(staging), done)
        (done / "setup.sh").write_text(SETUP_SH.replace("@PREFIX@", str(done)))
        check(done)
        (done / ".complete").write_text("")
    return done


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "sources", type=Path, help="the folder of source archives with MANIFEST.tsv"
    )
    parser.add_argument("--key", action="store_true", help="print the cache key and exit")
    parser.add_argument(
        "--missing", action="store_true", help="print the Debian packages it needs that are missing"
    )
    parser.add_argument(
        "--cached", action="store_true", help="print the prefix if it is built, else exit 3"
    )
    args = parser.parse_args(argv)
    try:
        if args.cached:
            done = cache_root() / f"prefix-{build_key(args.sources.resolve())}"
            if not (done / ".complete").is_file():
                return 3
            print(done)
        elif args.missing:
            print(" ".join(missing_debian_packages()))
        elif args.key:
            print(build_key(args.sources.resolve()))
        else:
            print(build(args.sources.resolve(), cache_root()))
    except (BuildError, OSError, tarfile.TarError) as error:
        print(f"scripts/ros1_sources/build.py: {error}", file=sys.stderr)
        return 2 if getattr(error, "cannot_run", False) else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
