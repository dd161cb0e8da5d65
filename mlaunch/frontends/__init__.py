"""The ROS 2 frontends: Python, YAML and XML launch files read into a LaunchDescription, strict
and located (every attribute consumed, errors with file:line:col). ``mlaunch.readers`` picks
one by suffix."""
