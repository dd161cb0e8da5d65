"""The smoke checks of ``mlaunch test``: expectations from the plan, the watch that attaches to a
run, the settings, the report and its JUnit file."""
