"""ROS 1: the roslaunch XML reader and the converters to ROS 2 files."""
