"""``launch_ros.substitutions.find_package``, where upstream defines it."""

from mlaunch.launch_ros.substitutions import FindPackage, FindPackagePrefix, FindPackageShare

__all__ = ["FindPackage", "FindPackagePrefix", "FindPackageShare"]
