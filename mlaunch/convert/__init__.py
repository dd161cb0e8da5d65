"""ROS 1 -> ROS 2 writers: a roslaunch model written as a Python, YAML or XML launch file."""
