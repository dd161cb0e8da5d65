"""``InvalidLaunchFileError``: a launch file that no loader could read, with what each raised."""

from __future__ import annotations

from collections.abc import Sequence


class InvalidLaunchFileError(Exception):
    """No loader accepted the file; ``likely_errors`` are what the loaders of its format raised."""

    def __init__(
        self, extension: str = "", *, likely_errors: Sequence[BaseException] | None = None
    ) -> None:
        super().__init__(extension)
        self._extension = extension
        self._likely_errors = list(likely_errors or [])
        if not extension or not self._likely_errors:
            self._error_message = (
                "The launch file may have a syntax error, or its format is unknown"
            )
            return
        many = len(self._likely_errors) > 1
        lines = [
            f"Caught {'multiple exceptions' if many else 'exception'} when trying to load file"
            f" of format [{extension}]:"
        ]
        lines += [f" - {type(error).__name__}: {error}" for error in self._likely_errors]
        self._error_message = "\n".join(lines)
        self.__cause__ = self._likely_errors[0]

    def __str__(self) -> str:
        return self._error_message
