"""The engine: runs a Plan. The supervisor loop, child processes, the stop ladder, signals,
the guard, respawn, the event handlers of the launch file, and the printer with its log files."""
