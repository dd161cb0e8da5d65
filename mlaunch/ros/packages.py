"""Finding ROS packages the way ROS 2 does, plus packages that are only checked out, not built.

An *installed* package is one an ament prefix of ``AMENT_PREFIX_PATH`` lists in its resource
index (``<prefix>/share/ament_index/resource_index/packages/<pkg>``): its share directory is
``<prefix>/share/<pkg>`` and its executables live in ``<prefix>/lib/<pkg>/``. The first prefix
that lists a package wins, as in ``ament_index_python``.

A *source* package is a folder holding a ``package.xml`` whose ``<name>`` is the package; its
share directory is that folder itself, so ``$(find pkg)`` and ``FindPackageShare`` work on a
fresh checkout (a robot description, a config folder) without colcon. Source packages come from,
in this order of precedence:

1. explicit paths: the run's ``PackageSearch`` (mlaunch.ros.search: the CLI's
   ``--package-path``) and ``MLAUNCH_PACKAGE_PATH`` (``os.pathsep`` separated); each is a
   package folder or a folder searched for package folders;
2. the source tree of each launch file in play (the CLI's launch file, the one being resolved,
   Python launch files running on the stack): from the file's folder up to the nearest folder
   holding ``.git``, ``pyproject.toml`` or ``COLCON_IGNORE`` (or, failing that, the folder above
   the launch file's own package), then searched;
3. for ``mlaunch PKG FILE`` only, the same for the current working directory.

An installed package always wins over a source package of the same name. Source folders are
only scanned when a name is not installed, and each scan is cached for the life of the process.
Nothing here imports rclpy.
"""

from __future__ import annotations

import os
import re
import sys

from mlaunch.plan import errors
from mlaunch.plan.value import Value
from mlaunch.ros.search import CONTEXT_KEY, PackageSearch, active

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable, Iterator, Mapping, Sequence
    from typing import Any

RESOURCE_INDEX = os.path.join("share", "ament_index", "resource_index")
ROOT_MARKERS = (".git", "pyproject.toml", "COLCON_IGNORE")
IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE", "CATKIN_IGNORE")
SKIPPED_DIRS = frozenset(
    {"build", "install", "log", "node_modules", "__pycache__", "site-packages"}
)
MAX_SCAN_DEPTH = 8
# REP 127 names (with its recommended exemptions), as ament_index_python checks them.
VALID_NAME = re.compile(r"[a-zA-Z0-9][a-zA-Z0-9_-]+", re.ASCII)


class PackageNotFoundError(errors.PackageNotFoundError, KeyError):
    """A package (or an executable in one) cannot be found.

    Also a KeyError/LookupError, like ``ament_index_python.packages.PackageNotFoundError``, so
    launch files that catch the ROS exception keep working.
    """

    def __str__(self) -> str:  # KeyError would quote the message
        return errors.PackageNotFoundError.__str__(self)


class Package(Value):
    """Where one package is: its share directory, and the prefix it is installed in."""

    _fields = ("name", "share_directory", "prefix", "installed", "standin")
    __slots__ = _fields

    def __init__(
        self, name: str, share_directory: str, prefix: str, installed: bool, standin: bool = False
    ) -> None:
        self.name = name
        self.share_directory = share_directory
        self.prefix = prefix  # the ament prefix; for a source package, its folder
        self.installed = installed
        self.standin = standin  # a share of mlaunch's stand-ins (mlaunch.standins.SHARE)

    @property
    def libexec_directory(self) -> str:
        return os.path.join(self.prefix, "lib", self.name)


_scan_cache: dict[str, dict[str, str]] = {}
_root_cache: dict[str, str | None] = {}


def forget_scans() -> None:
    """Forget every cached scan of source folders (tests; a long-lived process)."""
    _scan_cache.clear()
    _root_cache.clear()


# --- the index ------------------------------------------------------------------------------


class PackageIndex:
    """One view of the packages: ament prefixes from an environment, then source folders."""

    def __init__(
        self,
        environ: Mapping[str, str],
        explicit_paths: tuple[str, ...] = (),
        trees_from: tuple[str, ...] = (),
        standins: bool = False,
    ) -> None:
        self.environ = environ
        self.explicit_paths = explicit_paths
        self.trees_from = trees_from  # files or folders whose source trees are searched
        self.standins = standins  # the stand-ins' shares answer last (PackageSearch.standins)
        self._sources: dict[str, str] | None = None

    # --- ament prefixes -------------------------------------------------------------------------

    def ament_prefixes(self) -> list[str]:
        """The existing prefixes of AMENT_PREFIX_PATH, in order."""
        value = self.environ.get("AMENT_PREFIX_PATH", "")
        return [p for p in value.split(os.pathsep) if p and os.path.exists(p)]

    def installed(self, name: str) -> Package | None:
        if not name or "/" in name or "\\" in name:
            return None
        for prefix in self.ament_prefixes():
            if os.path.isfile(os.path.join(prefix, RESOURCE_INDEX, "packages", name)):
                share = os.path.join(prefix, "share", name)
                return Package(name, share, prefix, installed=True)
        return None

    def installed_packages(self) -> dict[str, str]:
        """Every installed package name -> the first prefix listing it."""
        found: dict[str, str] = {}
        for prefix in self.ament_prefixes():
            folder = os.path.join(prefix, RESOURCE_INDEX, "packages")
            try:
                entries = sorted(os.listdir(folder))
            except OSError:
                continue
            for entry in entries:
                if entry.startswith(".") or os.path.isdir(os.path.join(folder, entry)):
                    continue
                found.setdefault(entry, prefix)
        return found

    # --- source packages ------------------------------------------------------------------------

    def source_paths(self) -> list[str]:
        """Where source packages are looked for, in precedence order (for messages, too)."""
        paths: list[str] = []
        for path in self._explicit():
            if path not in paths:
                paths.append(path)
        for start in self.trees_from:
            root = source_root(start)
            if root is not None and root not in paths:
                paths.append(root)
        return paths

    def _explicit(self) -> list[str]:
        env_paths = self.environ.get("MLAUNCH_PACKAGE_PATH", "")
        from_env = [os.path.abspath(p) for p in env_paths.split(os.pathsep) if p]
        return [*self.explicit_paths, *from_env]

    def source_packages(self) -> dict[str, str]:
        """Every source package name -> its folder (the first one found wins)."""
        if self._sources is None:
            found: dict[str, str] = {}
            for path in self.source_paths():
                for name, folder in scan(path).items():
                    found.setdefault(name, folder)
            self._sources = found
        return self._sources

    def source(self, name: str) -> Package | None:
        folder = self.source_packages().get(name)
        if folder is None:
            return None
        return Package(name, folder, folder, installed=False)

    # --- lookups ------------------------------------------------------------------------------

    def standin_share(self, name: str) -> Package | None:
        """A stand-in's share of the package (its launch files), when stand-ins are on."""
        if not self.standins or not VALID_NAME.fullmatch(name):
            return None
        from mlaunch.standins import SHARE

        folder = os.path.join(SHARE, name)
        if not os.path.isfile(os.path.join(folder, "package.xml")):
            return None
        return Package(name, folder, folder, installed=False, standin=True)

    def find(self, name: str) -> Package | None:
        """The package: installed, else from source, else a stand-in's share; None: nowhere."""
        return self.installed(name) or self.source(name) or self.standin_share(name)

    def get(self, name: str) -> Package:
        """The package, or a PackageNotFoundError saying where it was looked for."""
        package = self.find(name)
        if package is None:
            from mlaunch.plan.errors import did_you_mean

            hint = did_you_mean(name, self.all_packages())
            raise PackageNotFoundError(
                f"package {name!r} not found{hint} ({self.searched()}){self._missing_hint(name)}"
            )
        return package

    def _missing_hint(self, name: str) -> str:
        """What a user does about a package found nowhere: install it, or let a stand-in serve."""
        if not self.standins and PackageIndex(self.environ, standins=True).standin_share(name):
            return "; mlaunch's stand-ins serve its launch files: run without --no-standins"
        return f"; mlaunch has no stand-in for it: install it ({install_hint(name)})"

    def all_packages(self) -> dict[str, Package]:
        out = {
            name: Package(name, os.path.join(prefix, "share", name), prefix, installed=True)
            for name, prefix in self.installed_packages().items()
        }
        for name, folder in self.source_packages().items():
            out.setdefault(name, Package(name, folder, folder, installed=False))
        return out

    def executable(self, package: str, executable: str) -> str:
        """``<prefix>/lib/<package>/<executable>``, as launch_ros's ExecutableInPackage finds it."""
        found = self.get(package)
        if found.standin:
            raise PackageNotFoundError(
                f"package {package!r} is not installed: mlaunch's stand-ins serve its launch"
                f" files, but not its executable {executable!r} (install the package:"
                f" {install_hint(package)})"
            )
        if not found.installed:
            raise PackageNotFoundError(
                f"package {package!r} is only a source package at {found.share_directory!r}:"
                f" its executable {executable!r} exists once the package is built and installed"
                " (colcon build, then source install/setup.bash)"
            )
        libexec = found.libexec_directory
        if not os.path.isdir(libexec):
            raise PackageNotFoundError(
                f"package {package!r} found at {found.prefix!r}, but its executable folder"
                f" {libexec!r} does not exist (wanted executable {executable!r})"
            )
        path = os.path.join(libexec, executable)
        if _is_program(path):
            return path
        have = sorted(
            e
            for e in os.listdir(libexec)
            if os.path.isfile(os.path.join(libexec, e))
            and os.access(os.path.join(libexec, e), os.X_OK)
        )
        from mlaunch.plan.errors import did_you_mean

        listing = f"; it has: {', '.join(have)}" if have else "; it has no executables"
        raise PackageNotFoundError(
            f"executable {executable!r} not found in package {package!r}"
            f"{did_you_mean(executable, have)} (looked in {libexec!r}{listing})"
        )

    def searched(self) -> str:
        """Where lookups went, for error messages."""
        prefixes = self.ament_prefixes()
        if "AMENT_PREFIX_PATH" not in self.environ or not self.environ["AMENT_PREFIX_PATH"]:
            where = "AMENT_PREFIX_PATH is not set"
        else:
            where = f"ament prefixes searched: {', '.join(prefixes) or '(none exist)'}"
        sources = self.source_paths()
        hint = (
            "; name the folders that hold it with --package-path DIR (repeatable) or"
            " MLAUNCH_PACKAGE_PATH=DIR[:DIR...], or source its workspace's setup"
        )
        if not sources:  # a launch file outside any repository, nothing named
            return f"{where}; no source folder to search{hint}"
        return f"{where}; source packages searched under: {', '.join(sources)}{hint}"


def install_hint(package: str) -> str:
    """How a ROS 2 Jazzy user gets a package: its Debian package name, as ROS packages them."""
    debian = f"ros-jazzy-{package.replace('_', '-')}"
    return f"sudo apt install {debian}, then source /opt/ros/jazzy/setup.bash"


def _is_program(path: str) -> bool:
    return os.path.isfile(path) and os.access(path, os.X_OK)


def index(
    *,
    search: PackageSearch | None = None,
    environ: Mapping[str, str] | None = None,
    launch_files: Iterable[str | None] = (),
    extra_paths: Sequence[str] = (),
    from_callers: bool = False,
    from_cwd: bool = False,
) -> PackageIndex:
    """The index for one lookup: a search (the active one by default) plus what the caller knows.

    ``launch_files`` are the launch files in play (the one being resolved); ``from_callers``
    adds the launch files whose code is on the Python stack, for lookups that have no context
    (``get_package_share_directory`` called while a launch file loads); ``from_cwd`` adds the
    source tree of the working directory (``mlaunch PKG FILE`` has no launch file yet).
    """
    search = active() if search is None else search
    starts: list[str] = []
    candidates: list[str | None] = [*launch_files, search.launch_file]
    if from_callers:
        candidates.extend(_launch_files_on_stack())
    if from_cwd:
        candidates.append(os.getcwd())
    for item in candidates:
        if item and item not in starts:
            starts.append(item)
    explicit = (*search.paths, *(os.path.abspath(p) for p in extra_paths if p))
    return PackageIndex(
        environ=search.environment() if environ is None else environ,
        explicit_paths=explicit,
        trees_from=tuple(starts),
        standins=search.standins,
    )


def for_context(context: Any) -> PackageIndex:
    """The index while resolving: the run's search, the context's environment and launch file."""
    search = context.locals.get(CONTEXT_KEY)
    return index(
        search=search if isinstance(search, PackageSearch) else None,
        environ=context.environment,
        launch_files=[context.current_launch_file_path],
    )


# The module name mlaunch's Python frontend runs a launch file as.
LAUNCH_MODULE_NAME = "python_launch_file"


def _launch_files_on_stack() -> Iterator[str]:
    """Python launch files whose code is running now (an include loads inside another).

    Only launch files count: a lookup from any other code (a test, a tool) that happens to
    use the launch_ros names gets no source packages from where that code lives.
    """
    frame = sys._getframe(1)
    while frame is not None:
        filename = frame.f_code.co_filename
        launch_module = frame.f_globals.get("__name__") == LAUNCH_MODULE_NAME
        if (launch_module or filename.endswith(".launch.py")) and os.path.isabs(filename):
            yield filename
        frame = frame.f_back  # type: ignore[assignment]


# --- source trees ---------------------------------------------------------------------------------


def source_root(start: str) -> str | None:
    """The folder to search for source packages around a launch file (or a folder).

    The nearest ancestor holding a repository marker; without one, the folder above the
    nearest package folder; else None (no scan of arbitrary parents).
    """
    folder = start if os.path.isdir(start) else os.path.dirname(start)
    folder = os.path.abspath(folder)
    if folder in _root_cache:
        return _root_cache[folder]
    root = None
    package_folder = None
    current = folder
    while True:
        if package_folder is None and os.path.isfile(os.path.join(current, "package.xml")):
            package_folder = current
        if any(os.path.exists(os.path.join(current, m)) for m in ROOT_MARKERS):
            root = current
            break
        parent = os.path.dirname(current)
        if parent == current:
            break
        current = parent
    if root is None and package_folder is not None:
        root = os.path.dirname(package_folder)
    _root_cache[folder] = root
    return root


def scan(path: str) -> dict[str, str]:
    """Source packages at or under ``path``: name -> folder (cached per path).

    A folder with a package.xml is a package and is not searched further (packages do not
    nest); hidden folders, build/install/log, virtualenvs and anything marked COLCON_IGNORE
    are skipped. Symlinked folders are followed (packages are often linked into a ``src``),
    each real folder once.
    """
    path = os.path.abspath(path)
    cached = _scan_cache.get(path)
    if cached is not None:
        return cached
    found: dict[str, str] = {}
    _scan_into(path, found, depth=0, seen=set(), top=True)
    _scan_cache[path] = found
    return found


def _scan_into(
    folder: str, found: dict[str, str], depth: int, seen: set[str], top: bool = False
) -> None:
    real = os.path.realpath(folder)
    if real in seen:  # a symlink loop, or a folder linked twice
        return
    seen.add(real)
    manifest = os.path.join(folder, "package.xml")
    if os.path.isfile(manifest):
        name = package_name(manifest)
        if name:
            found.setdefault(name, folder)
        return
    if depth >= MAX_SCAN_DEPTH:
        return
    try:
        entries = sorted(os.scandir(folder), key=lambda e: e.name)
    except OSError:
        return
    names = {e.name for e in entries}
    if not top and any(m in names for m in IGNORE_MARKERS):
        return
    for entry in entries:
        if not _skipped(entry):
            _scan_into(entry.path, found, depth + 1, seen)


def _skipped(entry: os.DirEntry[str]) -> bool:
    name = entry.name
    if name.startswith(".") or name in SKIPPED_DIRS:
        return True
    try:
        if not entry.is_dir():
            return True
    except OSError:
        return True
    # A virtualenv by any name (venv, env, ...) holds no ROS source packages.
    return os.path.isfile(os.path.join(entry.path, "pyvenv.cfg"))


def package_name(manifest: str) -> str | None:
    """The ``<name>`` of a package.xml, or None when the file is not a readable manifest."""
    import xml.etree.ElementTree as ET  # only when a source tree is scanned

    try:
        root = ET.parse(manifest).getroot()
    except (OSError, ET.ParseError):
        return None
    if root.tag != "package":
        return None
    text = root.findtext("name")
    return text.strip() if text and text.strip() else None


# --- what the CLI and ament_index use ---------------------------------------------------------


def find_launch_file(package: str, file_name: str) -> str:
    """``mlaunch PKG FILE``: the one file named ``file_name`` under the package's share folder.

    As ``ros2 launch``: an os.walk of the share directory for an exact basename; none or more
    than one match is an error.
    """
    found = index(from_cwd=True).get(package)
    share = found.share_directory
    matches: list[str] = []
    names: set[str] = set()  # every file name, for a did-you-mean
    for root, dirs, files in os.walk(share):
        if not found.installed:  # a checkout: leave out build trees and hidden folders
            dirs[:] = sorted(d for d in dirs if not d.startswith(".") and d not in SKIPPED_DIRS)
        else:
            dirs.sort()
        matches.extend(os.path.join(root, f) for f in sorted(files) if f == file_name)
        names.update(files)
    if not matches:
        raise errors.LaunchFileError(
            f"file {file_name!r} was not found in the share directory of package {package!r}"
            f" which is at {share!r}{errors.did_you_mean(file_name, sorted(names))}"
        )
    if len(matches) > 1:
        raise errors.LaunchFileError(
            f"file {file_name!r} was found more than once in the share directory of package"
            f" {package!r}: {', '.join(matches)} (give the path of the one to launch)"
        )
    return matches[0]


def check_name(name: str) -> None:
    """ament_index_python's package-name check (a ValueError, as there)."""
    if VALID_NAME.fullmatch(name) is None:
        raise ValueError(f"{name!r} is not a valid package name")


__all__ = [
    "Package",
    "PackageIndex",
    "PackageNotFoundError",
    "check_name",
    "find_launch_file",
    "for_context",
    "forget_scans",
    "index",
    "package_name",
    "scan",
    "source_root",
]
