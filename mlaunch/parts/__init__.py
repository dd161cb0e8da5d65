"""Parts that attach to a run and react to its record stream: runtime control and its socket, the
--status view and exit summary, lifecycle driving, the LoadNode driver and the rclpy bridge, and
processes on other machines (``remote``, ``ssh``, ``agent``, the program that runs over there)."""
