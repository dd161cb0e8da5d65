"""``--check``: what ros2 launch (Jazzy) would reject or read differently in a file."""
