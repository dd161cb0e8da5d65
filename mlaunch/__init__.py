"""mlaunch: a fast, trustworthy ROS 2 launcher."""

__version__ = "0.1.0"
