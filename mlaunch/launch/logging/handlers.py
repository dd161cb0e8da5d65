"""``launch.logging.handlers``: every handler of Python's ``logging`` and ``logging.handlers``,
each able to format the records of one logger its own way (``setFormatterFor``).

launch's process output loggers share the screen and launch-log handlers with launch's own
loggers but print bare lines; a formatter per logger name does that.
"""

from __future__ import annotations

import logging
import logging.handlers
from typing import Any


def with_per_logger_formatting(cls: type[logging.Handler]) -> type[logging.Handler]:
    """``cls`` with ``setFormatterFor(logger, formatter)`` and ``unsetFormatterFor(logger)``."""

    class PerLoggerFormatting(cls):  # type: ignore[valid-type, misc]
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            super().__init__(*args, **kwargs)
            self._formatters: dict[str, logging.Formatter] = {}

        def setFormatterFor(self, logger: Any, formatter: logging.Formatter) -> None:
            self._formatters[logger if isinstance(logger, str) else logger.name] = formatter

        def unsetFormatterFor(self, logger: Any) -> None:
            self._formatters.pop(logger if isinstance(logger, str) else logger.name, None)

        def format(self, record: logging.LogRecord) -> str:
            formatter = self._formatters.get(record.name)
            if formatter is not None:
                return formatter.format(record)
            return str(super().format(record))

    PerLoggerFormatting.__name__ = PerLoggerFormatting.__qualname__ = cls.__name__
    PerLoggerFormatting.__doc__ = cls.__doc__
    return PerLoggerFormatting


def _wrap_all() -> dict[str, type[logging.Handler]]:
    found: dict[str, type[logging.Handler]] = {}
    for module in (logging, logging.handlers):
        for name in dir(module):
            value = getattr(module, name)
            if (
                not name.startswith("_")
                and isinstance(value, type)
                and issubclass(value, logging.Handler)
            ):
                found[name] = with_per_logger_formatting(value)
    return found


_HANDLERS = _wrap_all()
globals().update(_HANDLERS)

__all__ = ["with_per_logger_formatting", *sorted(_HANDLERS)]
