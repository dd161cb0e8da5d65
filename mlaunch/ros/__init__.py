"""ROS package data on disk, no rclpy: the ament index, the run's package search, params files."""
