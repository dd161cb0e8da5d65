"""``launch_testing.post_shutdown_test``: test classes that run after the launch ended."""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable


def post_shutdown_test() -> Callable[[type], type]:
    """Mark a TestCase class to run after the launch has shut down."""

    def decorate(test_class: type) -> type:
        if not isinstance(test_class, type):
            raise TypeError(
                f"post_shutdown_test() decorates TestCase classes, not {type(test_class).__name__}"
            )
        test_class.__post_shutdown_test__ = True  # type: ignore[attr-defined]
        return test_class

    return decorate


__all__ = ["post_shutdown_test"]
