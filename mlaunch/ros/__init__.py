"""ROS-facing helpers: the ament index, node command lines, params files, and the rclpy bridge."""
