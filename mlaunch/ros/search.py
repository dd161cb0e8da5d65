"""Where ROS packages are looked for: an explicit input of a run, not a setting of the process.

A ``PackageSearch`` is what the command line says about finding packages (``--package-path``,
the launch file it names, the environment). The pipeline hands it to resolve in
``ResolveOptions.packages``; resolve puts it in the launch context's globals, where the ROS
substitutions and Node find it (``packages.for_context``).

``ament_index_python``'s functions take no context, and launch files call them while they are
loaded. For those lookups the pipeline makes its search the *active* one for the duration of
the load and the resolve (``with searching(search): ...``); outside that, lookups use the
default search (the process environment, ``MLAUNCH_PACKAGE_PATH``, the launch files on the
call stack). Kept apart from mlaunch.ros.packages so that a launch without ROS parts does not
load the package index.
"""

from __future__ import annotations

import os

from mlaunch.plan.value import Value

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

# The key of the launch context's globals that holds the run's PackageSearch.
CONTEXT_KEY = "mlaunch_package_search"


class PackageSearch(Value):
    """Explicit source-package folders, the top launch file, and the environment lookups use.

    ``environ`` None means the process environment at the time of the lookup; ``standins``
    False leaves out the stand-ins' shares (--no-standins).
    """

    _fields = ("paths", "launch_file", "environ", "standins")
    __slots__ = _fields

    def __init__(
        self,
        paths: Sequence[str] = (),
        launch_file: str | None = None,
        environ: Mapping[str, str] | None = None,
        standins: bool = True,
    ) -> None:
        self.paths: tuple[str, ...] = tuple(os.path.abspath(p) for p in paths if p)
        self.launch_file = os.path.abspath(launch_file) if launch_file else None
        self.environ = None if environ is None else dict(environ)
        # The stand-ins' own shares (mlaunch.standins.SHARE: ros_gz_sim's launch files, ...)
        # answer last, for a package found nowhere else; off with --no-standins.
        self.standins = standins

    def environment(self) -> Mapping[str, str]:
        return os.environ if self.environ is None else self.environ


DEFAULT = PackageSearch()
_active: list[PackageSearch] = []


def active() -> PackageSearch:
    """The search of the load or resolve running now (the default one outside any)."""
    return _active[-1] if _active else DEFAULT


class searching:
    """``with searching(search):`` makes ``search`` the active one inside, the previous after.

    A small class, not contextlib.contextmanager: contextlib costs ~0.7 ms at start-up.
    """

    __slots__ = ("search",)

    def __init__(self, search: PackageSearch) -> None:
        self.search = search

    def __enter__(self) -> PackageSearch:
        _active.append(self.search)
        return self.search

    def __exit__(self, *exc_info: object) -> None:
        _active.pop()
