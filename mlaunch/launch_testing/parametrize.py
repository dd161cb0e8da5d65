"""``launch_testing.parametrize``: one launch (and one run of the tests) per set of values."""

from __future__ import annotations

import functools

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Iterator
    from typing import Any


def parametrize(argnames: str, argvalues: Iterable[Any]) -> Callable[[Any], Any]:
    """Launch the test description once per value, like ``pytest.mark.parametrize``.

    ``argnames`` is comma separated; each value is a tuple (or one value for one name). The
    decorated function yields ``(description function, {name: value})`` pairs.
    """
    names = [name.strip() for name in argnames.split(",") if name.strip()]
    values = [v if isinstance(v, tuple) else (v,) for v in argvalues]

    def decorate(function: Any) -> Any:
        # wraps: the runs carry the function's name, markers, timeout and pytest marks, and
        # inspect.unwrap reaches the function (the runner checks its parameters).
        @functools.wraps(function)
        def runs() -> Iterator[tuple[Any, dict[str, Any]]]:
            for value in values:
                if len(value) != len(names):
                    raise ValueError(
                        f"parametrize({argnames!r}): value {value!r} has {len(value)} items,"
                        f" expected {len(names)}"
                    )
                bound = dict(zip(names, value, strict=True))
                partial = functools.partial(function, **bound)
                functools.update_wrapper(partial, function)
                yield partial, bound

        runs.__parametrized__ = True  # type: ignore[attr-defined]
        return runs

    return decorate


__all__ = ["parametrize"]
