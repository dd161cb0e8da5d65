"""Loading a Python launch file as a module and taking its description, as launch does."""

from __future__ import annotations

from importlib.machinery import SourceFileLoader
from importlib.util import module_from_spec, spec_from_loader
from types import ModuleType
from typing import Any

from mlaunch.launch.invalid_launch_file_error import InvalidLaunchFileError


class InvalidPythonLaunchFileError(InvalidLaunchFileError):
    """A Python launch file without ``generate_launch_description()``."""

    def __init__(self, message: str) -> None:
        super().__init__()
        self._error_message = message


def load_python_launch_file_as_module(python_launch_file_path: str) -> ModuleType:
    """The launch file at the path, executed as a module named ``python_launch_file``."""
    loader = SourceFileLoader("python_launch_file", str(python_launch_file_path))
    spec = spec_from_loader(loader.name, loader)
    if spec is None:
        raise RuntimeError(f"cannot make a module spec for {python_launch_file_path!r}")
    module = module_from_spec(spec)
    loader.exec_module(module)
    return module


def get_launch_description_from_python_launch_file(python_launch_file_path: str) -> Any:
    """What the file's ``generate_launch_description()`` returns."""
    module = load_python_launch_file_as_module(python_launch_file_path)
    generate = getattr(module, "generate_launch_description", None)
    if generate is None:
        raise InvalidPythonLaunchFileError(
            f"launch file at '{python_launch_file_path}' does not contain the required"
            " function 'generate_launch_description()'"
        )
    return generate()
