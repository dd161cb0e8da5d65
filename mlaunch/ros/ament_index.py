"""``ament_index_python`` (and ``.packages``) as launch files see them inside mlaunch.

Same names, arguments and exceptions as the real module, answered by mlaunch.ros.packages, so a
launch file calling ``get_package_share_directory('my_robot_description')`` also finds a package
that is only checked out (a folder with a package.xml near the launch file), not installed.
Installed packages (the ament index of ``AMENT_PREFIX_PATH``) always win.

For a source package, "prefix" is its folder: ``get_package_prefix`` returns it and
``get_package_share_directory`` returns the same folder (not ``<prefix>/share/<pkg>``).

The search (explicit folders, the launch file, the environment) is the one the running load or
resolve made active (mlaunch.ros.search), else the default one on ``os.environ``.
"""

from __future__ import annotations

import os
import pathlib
import warnings

# Not bound as ``packages``: compat serves ``ament_index_python.packages`` with this very module
# and the import system then sets ``<this module>.packages`` to the module itself.
from mlaunch.ros import packages as _packages
from mlaunch.ros import search as _search
from mlaunch.ros.packages import PackageNotFoundError

RESOURCE_INDEX_SUBFOLDER = "share/ament_index/resource_index"
AMENT_PREFIX_PATH_ENV_VAR = "AMENT_PREFIX_PATH"


class InvalidResourceTypeNameError(ValueError):
    """A resource type name with a path separator in it."""


class InvalidResourceNameError(ValueError):
    """A resource name with a path separator in it."""


def _index() -> _packages.PackageIndex:
    # No launch context here: the launch file being loaded is found on the call stack.
    return _packages.index(from_callers=True)


def get_search_paths() -> list[str]:
    """The existing prefixes of AMENT_PREFIX_PATH (an OSError when it is unset, as in ROS 2)."""
    environ = _search.active().environment()
    if not environ.get(AMENT_PREFIX_PATH_ENV_VAR):
        raise OSError(f"Environment variable '{AMENT_PREFIX_PATH_ENV_VAR}' is not set or empty")
    return _index().ament_prefixes()


def get_package_prefix(package_name: str) -> str:
    """The install prefix of a package (a source package's own folder)."""
    _packages.check_name(package_name)
    return _index().get(package_name).prefix


def get_package_share_directory(package_name: str, print_warning: bool = True) -> str:
    """The share directory of a package (a source package's own folder)."""
    _packages.check_name(package_name)
    path = _index().get(package_name).share_directory
    if print_warning and not os.path.exists(path):
        warnings.warn(f"Share directory for {package_name} ({path}) does not exist.", stacklevel=2)
    return path


def get_package_share_path(package_name: str, print_warning: bool = True) -> pathlib.Path:
    path = pathlib.Path(get_package_share_directory(package_name, print_warning=False))
    if print_warning and not path.exists():
        warnings.warn(f"Share path for {package_name} ({path}) does not exist.", stacklevel=2)
    return path


def get_packages_with_prefixes() -> dict[str, str]:
    """Every package name -> its prefix; source packages map to their folders."""
    return {name: found.prefix for name, found in _index().all_packages().items()}


def _check_resource_names(resource_type: str, resource_name: str | None = None) -> None:
    if not resource_type:
        raise ValueError("The resource type must not be empty")
    if "/" in resource_type or "\\" in resource_type:
        raise InvalidResourceTypeNameError(f"Resource type '{resource_type}' is invalid")
    if resource_name is not None:
        if not resource_name:
            raise ValueError("The resource name must not be empty")
        if "/" in resource_name or "\\" in resource_name:
            raise InvalidResourceNameError(f"Resource name '{resource_name}' is invalid")


def get_resource(resource_type: str, resource_name: str) -> tuple[str, str]:
    """(content, prefix) of a resource in the ament index; a source package is a 'packages'
    resource with empty content in its own folder."""
    _check_resource_names(resource_type, resource_name)
    index = _index()
    for prefix in index.ament_prefixes():
        path = os.path.join(prefix, RESOURCE_INDEX_SUBFOLDER, resource_type, resource_name)
        if os.path.isfile(path):
            try:
                with open(path, encoding="utf-8") as f:
                    return f.read(), prefix
            except OSError as e:
                raise OSError(
                    f"Could not open the resource '{resource_name}' of type '{resource_type}':\n{e}"
                )
    if resource_type == "packages":
        source = index.source(resource_name)
        if source is not None:
            return "", source.prefix
    raise LookupError(f"Could not find the resource '{resource_name}' of type '{resource_type}'")


def get_resources(resource_type: str) -> dict[str, str]:
    """Every resource name of a type -> its prefix."""
    _check_resource_names(resource_type)
    if resource_type == "packages":
        return get_packages_with_prefixes()
    found: dict[str, str] = {}
    for prefix in _index().ament_prefixes():
        folder = os.path.join(prefix, RESOURCE_INDEX_SUBFOLDER, resource_type)
        if not os.path.isdir(folder):
            continue
        for name in sorted(os.listdir(folder)):
            if name.startswith(".") or os.path.isdir(os.path.join(folder, name)):
                continue
            found.setdefault(name, prefix)
    return found


def get_resource_types() -> set[str]:
    types: set[str] = set()
    for prefix in _index().ament_prefixes():
        folder = os.path.join(prefix, RESOURCE_INDEX_SUBFOLDER)
        if os.path.isdir(folder):
            types.update(
                t
                for t in os.listdir(folder)
                if not t.startswith(".") and os.path.isdir(os.path.join(folder, t))
            )
    return types


def has_resource(resource_type: str, resource_name: str) -> str | bool:
    """The prefix holding the resource, or False."""
    try:
        return get_resource(resource_type, resource_name)[1]
    except LookupError:
        return False


__all__ = [
    "AMENT_PREFIX_PATH_ENV_VAR",
    "RESOURCE_INDEX_SUBFOLDER",
    "InvalidResourceNameError",
    "InvalidResourceTypeNameError",
    "PackageNotFoundError",
    "get_package_prefix",
    "get_package_share_directory",
    "get_package_share_path",
    "get_packages_with_prefixes",
    "get_resource",
    "get_resource_types",
    "get_resources",
    "get_search_paths",
    "has_resource",
]
