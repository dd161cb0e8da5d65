"""``FilePath``: what launch's file arguments accept (str, bytes or a path-like object)."""

import os
import typing

FilePath = typing.TypeVar("FilePath", str, bytes, os.PathLike)  # type: ignore[type-arg]
