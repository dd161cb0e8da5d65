"""ROS-facing helpers: the ament index, package search, node command lines, params files, xacro,
lifecycle driving and the rclpy bridge (the only place rclpy is imported, lazily)."""
