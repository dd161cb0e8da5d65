"""Running a launch as an application: the options of ``mlaunch FILE``, the pipeline (load,
resolve, supervise with the standard parts), ``launch.LaunchService``, and the finder that serves
the ROS 2 module names (``compat``)."""
