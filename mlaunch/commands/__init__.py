"""The subcommands of the mlaunch CLI: ``test`` (smoke), ``convert``, ``export``, ``ctl``."""
