"""launch_testing_ros's pytest plugin (``hooks``): launch tests marked ``rostest``."""
