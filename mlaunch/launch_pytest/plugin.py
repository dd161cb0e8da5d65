"""The pytest plugin behind launch_pytest: launch fixtures, ``@pytest.mark.launch`` tests.

- A ``@launch_pytest.fixture`` runs its launch on a LaunchService in a thread (LaunchRun).
- ``@pytest.mark.launch(fixture=F)`` tests get F set up even if they do not name it, and can
  name ``launch_service`` and ``launch_context``. ``shutdown=True`` tests run after F's launch
  was shut down; they are moved after F's other tests (per fixture instance, so per parameter).
- Tests may be plain, ``async``, generators or async generators: the code after a ``yield``
  runs once the launch was shut down, after the ``shutdown=True`` tests of the same instance.
- The ROS 2 module names (``launch``, ``launch_pytest`` ...) are served by mlaunch from the
  first test module that imports one of them on (launch_testing's plugin does that).
"""

from __future__ import annotations

import asyncio
import inspect
import threading
from collections.abc import Sequence

import pytest

from mlaunch.app.launch_service import LaunchService
from mlaunch.launch.actions.register_event_handler import RegisterEventHandler
from mlaunch.launch.event_handlers.on_process_exit import OnProcessExit
from mlaunch.launch.event_handlers.on_process_io import OnProcessIO
from mlaunch.launch.event_handlers.on_process_start import OnProcessStart
from mlaunch.launch.launch_description import LaunchDescription
from mlaunch.launch_testing.actions import ReadyToTest
from mlaunch.launch_testing.io_handler import ActiveIoHandler
from mlaunch.launch_testing.loader import iter_ready_to_test
from mlaunch.launch_testing.proc_info_handler import ActiveProcInfoHandler

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from typing import Any

    from mlaunch.ros.domain import Isolation

# How long a launch fixture waits for its ReadyToTest, and for its launch to end at shutdown.
READY_TIMEOUT = 15.0
END_TIMEOUT = 60.0


class LaunchRun:
    """One launch fixture's launch: its service, thread, recorders and deferred test parts."""

    _by_value: dict[int, LaunchRun] = {}

    def __init__(self, value: Any, service: LaunchService, auto_shutdown: bool) -> None:
        self.value = value
        self.service = service
        self.auto_shutdown = auto_shutdown
        self.proc_info = ActiveProcInfoHandler()
        self.proc_output = ActiveIoHandler()
        self.ready = threading.Event()
        self.thread: threading.Thread | None = None
        self.deferred: list[Callable[[], None]] = []
        self.stopped = False
        self.isolation: Isolation | None = None
        # One asyncio loop for the async tests of this launch: an async generator test's two
        # halves must run on the same loop (closing a loop finalizes its async generators).
        self._loop: asyncio.AbstractEventLoop | None = None

    @property
    def loop(self) -> asyncio.AbstractEventLoop:
        """The asyncio loop the async tests of this launch run on (the ``event_loop`` fixture)."""
        if self._loop is None:
            self._loop = asyncio.new_event_loop()
        return self._loop

    def run_coroutine(self, coroutine: Any) -> Any:
        return self.loop.run_until_complete(coroutine)

    @classmethod
    def start(
        cls, value: Any, *, name: str, shutdown_when_idle: bool, auto_shutdown: bool
    ) -> LaunchRun:
        """Launch what the fixture ``name`` returned, in a thread; wait for its ReadyToTest."""
        from mlaunch.ros.domain import Isolation

        description = _description_of(value, name)
        isolation = Isolation()  # a ROS domain of its own, unless the user set one
        run = cls(value, LaunchService(), auto_shutdown)
        run.isolation = isolation
        ready = _the_ready_to_test(description)
        ready._add_callback(run.ready.set)
        recorders.register(run.service.context, run)
        run.service.include_launch_description(run.recording(description))
        cls._by_value[id(value)] = run
        run.thread = run.service.run_in_thread(shutdown_when_idle=shutdown_when_idle)
        if not run.ready.wait(READY_TIMEOUT):
            run.finish()
            raise RuntimeError(f"the launch did not reach its ReadyToTest within {READY_TIMEOUT} s")
        return run

    @classmethod
    def of(cls, value: Any) -> LaunchRun:
        return cls._by_value[id(value)]

    def recording(self, description: LaunchDescription) -> LaunchDescription:
        """``description`` with handlers that record process events for launch_pytest.tools."""
        info, output = self.proc_info, self.proc_output
        return LaunchDescription(
            [
                RegisterEventHandler(OnProcessStart(on_start=lambda e, c: info.append(e))),
                RegisterEventHandler(
                    OnProcessStart(on_start=lambda e, c: output.track(e.process_name))
                ),
                RegisterEventHandler(OnProcessExit(on_exit=lambda e, c: info.append(e))),
                RegisterEventHandler(OnProcessIO(on_stdout=output.append, on_stderr=output.append)),
                description,
            ]
        )

    def stop(self) -> None:
        """Shut the launch down (or, without auto_shutdown, let it end) and wait for it."""
        if self.stopped:
            return
        self.stopped = True
        if self.auto_shutdown:
            self.service.shutdown()
        if self.thread is not None:
            self.thread.join(END_TIMEOUT)
            if self.thread.is_alive():
                self.service.shutdown()
                self.thread.join(END_TIMEOUT)
                raise RuntimeError(f"the launch did not end within {END_TIMEOUT} s")

    def run_deferred(self) -> None:
        """The code after the ``yield`` of generator tests, in the order they ran."""
        deferred, self.deferred = self.deferred, []
        for part in deferred:
            part()

    def finish(self) -> None:
        try:
            self.stop()
            self.run_deferred()
        finally:
            self._by_value.pop(id(self.value), None)
            if self.isolation is not None:
                self.isolation.end()
            if self._loop is not None:
                self._loop.close()
                self._loop = None


class _Recorders:
    """launch_context -> its LaunchRun, for launch_pytest.tools (the context is what tests hold)."""

    def __init__(self) -> None:
        self._runs: dict[int, tuple[Any, LaunchRun]] = {}

    def register(self, context: Any, run: LaunchRun) -> None:
        self._runs[id(context)] = (context, run)

    def of(self, context: Any) -> LaunchRun:
        found = self._runs.get(id(context))
        if found is None or found[0] is not context:
            raise ValueError("this launch_context does not belong to a launch_pytest fixture")
        return found[1]


recorders = _Recorders()


def _description_of(value: Any, fixture_name: str) -> LaunchDescription:
    """The LaunchDescription a launch fixture returned: the value, or the first item of the
    sequence it returned; anything else is an error naming the fixture (as launch_pytest's)."""
    description = value
    if isinstance(value, Sequence):
        description = value[0] if len(value) else None
    if not isinstance(description, LaunchDescription):
        raise TypeError(
            f"When running launch_pytest fixture '{fixture_name}': return value must be either a"
            " launch description or a sequence which first item is a launch description"
            f" (got {type(value).__name__})"
        )
    return description


def _the_ready_to_test(description: LaunchDescription) -> ReadyToTest:
    """The one ReadyToTest of ``description`` (one is added at its end when it has none)."""
    found = list(iter_ready_to_test(description.entities))
    if len(found) > 1:
        raise RuntimeError(
            "launch_pytest fixtures must return a LaunchDescription containing only one"
            f" ReadyToTest action (this one has {len(found)})"
        )
    if found:
        return found[0]
    ready = ReadyToTest()
    description.add_action(ready)
    return ready


# --- markers and fixtures ---------------------------------------------------------------------


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "launch(fixture, shutdown=False): run the test with the launch of a launch_pytest"
        " fixture (after it was shut down when shutdown=True)",
    )


class LaunchTestWarning(pytest.PytestWarning):
    """A launch test written in a way launch_pytest cannot run."""


NO_FIXTURE = '"fixture" keyword argument is required in a pytest.mark.launch() decorator'


def _launch_marker(item: Any) -> Any:
    """The item's ``launch`` mark, when it names a fixture (without one the item is skipped)."""
    marker = item.get_closest_marker("launch")
    if marker is None or marker.kwargs.get("fixture") is None:
        return None
    return marker


def _skip_without_fixture(item: Any) -> None:
    """A ``launch`` mark without ``fixture=``: warned about and skipped, as in launch_pytest."""
    marker = item.get_closest_marker("launch")
    if marker is not None and marker.kwargs.get("fixture") is None:
        item.warn(LaunchTestWarning(NO_FIXTURE))
        item.add_marker(pytest.mark.skip(reason=NO_FIXTURE))


def fixture_marker(fixture: Any) -> Any:
    """pytest's FixtureFunctionMarker (scope, name, params) of a fixture, or None.

    pytest 8.4 and later return a FixtureFunctionDefinition from ``@pytest.fixture``, holding it
    as ``_fixture_function_marker``; earlier ones (7.4, what ROS 2 Jazzy runs, included) return
    the function itself with the marker as ``_pytestfixturefunction``.
    """
    for attribute in ("_fixture_function_marker", "_pytestfixturefunction"):
        marker = getattr(fixture, attribute, None)
        if marker is not None:
            return marker
    return None


def _fixture_name(marker: Any) -> str:
    fixture = marker.kwargs["fixture"]
    definition = fixture_marker(fixture)
    if definition is None:
        raise pytest.UsageError(f"@pytest.mark.launch(fixture={fixture!r}) is not a fixture")
    return str(definition.name or fixture.__name__)


def _run_of(request: pytest.FixtureRequest) -> LaunchRun:
    marker = _launch_marker(request.node)
    if marker is None:
        raise pytest.UsageError(
            f"{request.node.nodeid}: launch_service and launch_context need"
            " @pytest.mark.launch(fixture=...)"
        )
    return LaunchRun.of(request.getfixturevalue(_fixture_name(marker)))


@pytest.fixture
def launch_service(request: pytest.FixtureRequest) -> LaunchService:
    """The LaunchService running the test's launch fixture."""
    return _run_of(request).service


@pytest.fixture
def launch_context(request: pytest.FixtureRequest) -> Any:
    """The launch context of the test's launch fixture (for launch_pytest.tools)."""
    return _run_of(request).service.context


@pytest.fixture
def event_loop(request: pytest.FixtureRequest) -> Iterator[asyncio.AbstractEventLoop]:
    """The asyncio loop a test's coroutines run on: its launch's for a launch test (closed when
    the launch is done), else a new loop closed after the test, as launch_pytest's fixture."""
    if _launch_marker(request.node) is not None:
        yield _run_of(request).loop
        return
    loop = asyncio.new_event_loop()
    try:
        yield loop
    finally:
        loop.close()


# --- collection -----------------------------------------------------------------------------


@pytest.hookimpl(tryfirst=True)
def pytest_pycollect_makeitem(collector: Any, name: str, obj: Any) -> Any:
    """Generator tests marked ``launch`` are tests here (pytest refuses yield tests).

    With a launch fixture wider than a function, a generator test is two items of the same
    name, as in ROS 2: the second runs the code after its ``yield``, after the shutdown.
    """
    if not collector.funcnamefilter(name) or not callable(obj):
        return None
    marks = [m for m in getattr(obj, "pytestmark", []) if m.name == "launch"]
    if not marks or not _is_generator(obj):
        return None
    items = list(collector._genfunctions(name, obj))
    if _scope_of(marks[0].kwargs.get("fixture")) != "function":
        halves = list(collector._genfunctions(name, obj))
        for item, half in zip(items, halves, strict=True):
            half._launch_pytest_shutdown_of = item
        items += halves
    return items


def _is_generator(function: Any) -> bool:
    return inspect.isgeneratorfunction(function) or inspect.isasyncgenfunction(function)


def _scope_of(fixture: Any) -> str:
    return str(getattr(fixture_marker(fixture), "scope", "function"))


def _is_shutdown_item(item: Any) -> bool:
    marker = _launch_marker(item)
    shutdown = bool(marker.kwargs.get("shutdown", False))
    return shutdown or hasattr(item, "_launch_pytest_shutdown_of")


def pytest_collection_modifyitems(session: Any, config: Any, items: list[Any]) -> None:
    """Every marked test gets its launch fixture; per fixture instance, the tests that run
    after the shutdown move after the others (each group keeps its own order)."""
    groups: dict[tuple[Any, ...], list[Any]] = {}
    for item in items:
        _skip_without_fixture(item)
        marker = _launch_marker(item)
        if marker is None:
            continue
        name = _fixture_name(marker)
        if name not in item.fixturenames:
            item.fixturenames.append(name)
        groups.setdefault(_instance_key(item, name), []).append(item)
    for members in groups.values():
        places = sorted(items.index(i) for i in members)
        ordered = sorted(members, key=lambda i: (_is_shutdown_item(i), items.index(i)))
        for place, item in zip(places, ordered, strict=True):
            items[place] = item
        ordered[-1]._launch_pytest_last = True


def _instance_key(item: Any, name: str) -> tuple[Any, ...]:
    """What identifies one instance of the launch fixture ``name`` for ``item``."""
    definitions = getattr(item, "_fixtureinfo", None)
    scope = "function"
    if definitions is not None and name in definitions.name2fixturedefs:
        scope = definitions.name2fixturedefs[name][-1].scope
    callspec = getattr(item, "callspec", None)
    param = callspec.params.get(name, None) if callspec is not None else None
    where: Any = {
        "function": item.nodeid,
        "class": (item.module.__name__, getattr(item.cls, "__name__", None)),
        "module": getattr(item.module, "__name__", None),
        "package": None,
        "session": None,
    }.get(str(scope), item.nodeid)
    return (name, where, repr(param))


# --- running tests --------------------------------------------------------------------------


@pytest.hookimpl(tryfirst=True)
def pytest_pyfunc_call(pyfuncitem: Any) -> Any:
    marker = _launch_marker(pyfuncitem)
    if marker is None:
        return None
    if marker.kwargs.get("shutdown", False) and _is_generator(pyfuncitem.obj):
        pytest.fail(
            "generator or async generator based launch test items cannot be marked with"
            " shutdown=True",
            pytrace=False,
        )
    run = LaunchRun.of(pyfuncitem.funcargs[_fixture_name(marker)])
    try:
        first_half = getattr(pyfuncitem, "_launch_pytest_shutdown_of", None)
        if first_half is not None:
            run.stop()
            rest = getattr(first_half, "_launch_pytest_rest", None)
            if rest is None:
                pytest.skip("shutdown test skipped because the test failed before")
            rest()
            return True
        if marker.kwargs.get("shutdown", False):
            run.stop()
        kwargs = {arg: pyfuncitem.funcargs[arg] for arg in pyfuncitem._fixtureinfo.argnames}
        rest = _call(pyfuncitem.obj, kwargs, run)
        if rest is not None:
            pyfuncitem._launch_pytest_rest = rest  # its own shutdown item runs it, or the end
            if not _has_shutdown_half(pyfuncitem):
                run.deferred.append(rest)
    finally:
        if getattr(pyfuncitem, "_launch_pytest_last", False):
            run.stop()
            run.run_deferred()
    return True


def _has_shutdown_half(item: Any) -> bool:
    marker = _launch_marker(item)
    return _scope_of(marker.kwargs.get("fixture")) != "function"


def _call(function: Any, kwargs: dict[str, Any], run: LaunchRun) -> Callable[[], None] | None:
    """Call a test of any kind; for a generator, return what finishes it (after the yield)."""
    if inspect.iscoroutinefunction(function):
        run.run_coroutine(function(**kwargs))
    elif inspect.isasyncgenfunction(function):
        agen = function(**kwargs)
        run.run_coroutine(_first(agen))
        return lambda: run.run_coroutine(_rest(agen))
    elif inspect.isgeneratorfunction(function):
        gen = function(**kwargs)
        next(gen, None)
        return lambda: _finish(gen)
    else:
        function(**kwargs)
    return None


async def _first(agen: Any) -> None:
    await agen.__anext__()


async def _rest(agen: Any) -> None:
    async for _ in agen:
        pytest.fail(
            "launch tests using an async gen function must stop iteration after yielding once",
            pytrace=False,
        )


def _finish(gen: Any) -> None:
    for _ in gen:
        pytest.fail(
            "launch tests using a generator function must stop iteration after yielding once",
            pytrace=False,
        )
