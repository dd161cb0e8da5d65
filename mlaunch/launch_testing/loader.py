"""A launch test file -> TestRuns: one launch (per parameter set) and the tests bound to it.

Tests are unittest TestCases. Those of classes marked ``post_shutdown_test`` run after the
launch ended; the others ("active" tests) run while it is up. A test method, setUp/tearDown and
setUpClass/tearDownClass receive what they name as parameters: ``proc_output``,
``proc_info``, ``launch_service``, ``test_args``, the items of the dictionary
``generate_test_description`` returned with its description, and the parametrized values.
"""

from __future__ import annotations

import functools
import inspect
import unittest

from mlaunch.launch_testing.actions.ready import ReadyToTest

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Iterator
    from types import ModuleType
    from typing import Any

DEFAULT_READY_TIMEOUT = 15.0


class TestRun:
    """One launch of the test description, with its own copies of the test classes."""

    def __init__(
        self,
        name: str,
        description_function: Callable[..., Any],
        param_args: dict[str, Any],
        pre_shutdown_tests: unittest.TestSuite,
        post_shutdown_tests: unittest.TestSuite,
    ) -> None:
        self.name = name
        self.description_function = description_function
        self.param_args = param_args
        self.pre_shutdown_tests = pre_shutdown_tests
        self.post_shutdown_tests = post_shutdown_tests
        self.timeout = float(
            getattr(description_function, "__ready_to_test_action_timeout__", None)
            or DEFAULT_READY_TIMEOUT
        )
        if param_args:
            # test_x becomes test_x[value, ...], so the report says which launch it ran on.
            for case in self.all_cases():
                method = getattr(case, case._testMethodName)
                renamed = case._testMethodName + self._format_params()
                case._testMethodName = renamed
                setattr(case, renamed, method)
        # unittest drops each test from its suite after running it; JUnit reports need them.
        for suite in _suites(self.pre_shutdown_tests, self.post_shutdown_tests):
            suite._removeTestAtIndex = lambda index: None  # type: ignore[attr-defined]

    @property
    def markers(self) -> dict[str, Any]:
        function = inspect.unwrap(self.description_function)
        markers: dict[str, Any] = getattr(self.description_function, "__markers__", None) or (
            getattr(function, "__markers__", None) or {}
        )
        return markers

    def normalized_test_description(self, *, ready_fn: Callable[[], object]) -> tuple[Any, Any]:
        """(launch description, test context), with ``ready_fn`` on its ReadyToTest.

        ``generate_test_description`` returns a description or (description, context); the
        description must hold a ReadyToTest, however deep (groups, timers, handlers).
        """
        result = self.description_function()
        description, context = result if isinstance(result, tuple) else (result, {})
        ready = next(iter_ready_to_test(getattr(description, "entities", [])), None)
        if ready is None:
            raise Exception(
                "generate_test_description functions must return a LaunchDescription"
                " containing a ReadyToTest action"
            )
        ready._add_callback(ready_fn)
        return description, context

    def get_launch_description(self) -> Any:
        """The description alone, for --show-args (not meant to be launched)."""
        return self.normalized_test_description(ready_fn=lambda: None)[0]

    def bind(
        self,
        tests: Any,
        injected_attributes: dict[str, Any] | None = None,
        injected_args: dict[str, Any] | None = None,
    ) -> None:
        """Give the tests ``injected_args`` as the parameters they name (test methods, setUp,
        tearDown, setUpClass, tearDownClass), and ``injected_attributes`` as ``self.NAME``
        (launch_testing's older way)."""
        values = injected_args or {}
        for case in _cases(tests):
            method = getattr(case, case._testMethodName)
            setattr(case, case._testMethodName, _bind_matching(method, values))
            case.setUp = _bind_matching(case.setUp, values)  # type: ignore[method-assign]
            case.tearDown = _bind_matching(case.tearDown, values)  # type: ignore[method-assign]
        for cls in _classes(tests):
            cls.setUpClass = _bind_matching(cls.setUpClass, values)  # type: ignore[method-assign]
            cls.tearDownClass = _bind_matching(cls.tearDownClass, values)  # type: ignore[method-assign]
            for name, value in (injected_attributes or {}).items():
                setattr(cls, name, value)

    def all_cases(self) -> Iterator[unittest.TestCase]:
        yield from _cases(self.pre_shutdown_tests)
        yield from _cases(self.post_shutdown_tests)

    def _format_params(self) -> str:
        if not self.param_args:
            return ""
        return "[" + ", ".join(str(v) for v in self.param_args.values()) + "]"

    def __str__(self) -> str:
        return self.name + self._format_params()


def iter_ready_to_test(entities: Iterable[Any]) -> Iterator[ReadyToTest]:
    """Every ReadyToTest in ``entities``, looking into groups, timers, handlers and includes."""
    for entity in entities:
        if isinstance(entity, ReadyToTest):
            yield entity
        yield from iter_ready_to_test(_children(entity))


def _children(entity: Any) -> list[Any]:
    found: list[Any] = list(getattr(entity, "entities", None) or [])
    sub = getattr(entity, "get_sub_entities", None)
    if sub is not None:
        found += sub()
    handler = getattr(entity, "event_handler", None)
    if handler is not None:
        found += list(getattr(handler, "entities", None) or [])
    source = getattr(entity, "launch_description_source", None)
    if source is not None and getattr(source, "launch_description", None) is not None:
        found.append(source.launch_description)
    return found


def LoadTestsFromPythonModule(module: ModuleType, *, name: str = "launch_tests") -> list[TestRun]:
    """The TestRuns of a launch test module: one, or one per value set when its
    generate_test_description is parametrized."""
    generate = getattr(module, "generate_test_description", None)
    if generate is None:
        raise Exception(
            f"{getattr(module, '__file__', None) or module.__name__}: a launch test file must"
            " define generate_test_description()"
        )
    parametrized = getattr(generate, "__parametrized__", False)
    runs = list(generate()) if parametrized else [(generate, {})]
    return [
        TestRun(
            name,
            function,
            args,
            PreShutdownTestLoader().loadTestsFromModule(module),
            PostShutdownTestLoader().loadTestsFromModule(module),
        )
        for function, args in runs
    ]


def PreShutdownTestLoader() -> unittest.TestLoader:
    """A loader of a module's active test classes (those not marked post_shutdown_test)."""
    return _loader(post_shutdown=False)


def PostShutdownTestLoader() -> unittest.TestLoader:
    """A loader of a module's post_shutdown_test classes."""
    return _loader(post_shutdown=True)


def _loader(*, post_shutdown: bool) -> unittest.TestLoader:
    class Loader(unittest.TestLoader):
        """Loads only the active (or only the post-shutdown) test classes, each as a fresh
        subclass, so that binding one launch's values never touches another's tests."""

        def loadTestsFromTestCase(self, testCaseClass: Any) -> unittest.TestSuite:
            if bool(getattr(testCaseClass, "__post_shutdown_test__", False)) != post_shutdown:
                return unittest.TestSuite()
            copy = type(
                testCaseClass.__name__, (testCaseClass,), {"__module__": testCaseClass.__module__}
            )
            return super().loadTestsFromTestCase(copy)

    return Loader()


def _bind_matching(function: Callable[..., Any], values: dict[str, Any]) -> Callable[..., Any]:
    parameters = inspect.signature(function).parameters
    return functools.partial(function, **{k: v for k, v in values.items() if k in parameters})


def _cases(suite: Any) -> Iterator[unittest.TestCase]:
    if isinstance(suite, unittest.TestCase):
        yield suite
        return
    for item in suite:
        yield from _cases(item)


def _classes(suite: Any) -> list[type[unittest.TestCase]]:
    seen: list[type[unittest.TestCase]] = []
    for case in _cases(suite):
        if type(case) not in seen:
            seen.append(type(case))
    return seen


def _suites(*suites: Any) -> Iterator[unittest.TestSuite]:
    for suite in suites:
        if isinstance(suite, unittest.TestSuite):
            yield suite
            yield from _suites(*suite)
