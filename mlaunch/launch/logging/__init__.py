"""``launch.logging``: launch's loggers, its screen and log-file handlers, and process output
loggers, for scripts and extensions that log as launch does.

mlaunch's own runs print through its engine (mlaunch.engine.output); this module is the API
that launch offers Python code: ``get_logger``, ``launch_config`` (level, log folder, screen and
log formats, handler factory), ``get_output_loggers`` and ``reset``. Importing it makes every
logger created afterwards a launch logger (not propagating to the root), as launch does.
"""

from __future__ import annotations

import datetime
import logging
import os
import socket
import sys
import warnings
from typing import Any

from mlaunch.launch.logging import handlers

__all__ = ["get_logger", "get_output_loggers", "handlers", "launch_config", "reset"]

FORMAT_ALIASES = {
    "default": "[{levelname}] [{name}]: {msg}",
    "default_with_timestamp": "{created:.7f} [{levelname}] [{name}]: {msg}",
}
LOG_FORMAT_DEFAULT = "{created:.7f} [{levelname}] [{name}]: {msg}"


def _get_logging_directory() -> str:
    """$ROS_LOG_DIR, else $ROS_HOME/log, else ~/.ros/log (empty counts as unset; ~ expanded)."""
    log_dir = os.environ.get("ROS_LOG_DIR")
    if not log_dir:
        log_dir = os.path.join(os.environ.get("ROS_HOME") or os.path.join("~", ".ros"), "log")
    return os.path.normpath(os.path.expanduser(log_dir))


def _make_unique_log_dir(*, base_path: str) -> str:
    """A new folder under ``base_path`` named by the time, the host and this process."""
    while True:
        stamp = datetime.datetime.now().strftime("%Y-%m-%d-%H-%M-%S-%f")
        path = os.path.join(base_path, f"{stamp}-{socket.gethostname()}-{os.getpid()}")
        if not os.path.isdir(path):
            os.makedirs(path, exist_ok=True)
            return path


def _renew_latest_log_dir(*, log_dir: str) -> bool:
    """Point ``latest`` next to ``log_dir`` at it; False when something else has that name."""
    latest = os.path.join(os.path.dirname(log_dir), "latest")
    if os.path.lexists(latest):
        if not os.path.islink(latest):
            return False
        os.unlink(latest)
    os.symlink(log_dir, latest, target_is_directory=True)
    return True


def _formatter(text: str | None, style: str | None, env: str, what: str) -> Any:
    """A ``{``-style formatter for ``text`` (an alias, or the override in ``env``)."""
    override = os.environ.get(env)
    if override:
        text, style = override.encode("latin1").decode("unicode_escape"), "{"
    if text is None:
        return None
    aliases = FORMAT_ALIASES if what == "screen" else {"default": LOG_FORMAT_DEFAULT}
    if text in aliases:
        if style is not None:
            raise ValueError(f'Cannot set a custom format style for the "{text}" {what} format.')
        text = aliases[text]
    return logging.Formatter(text, style=style or "{")  # type: ignore[arg-type]


class LaunchConfig:
    """Where and how launch logs: level, folder, formats, handlers (one per file, one screen)."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self._log_dir: str | None = None
        self.file_handlers: dict[str, Any] = {}
        self.screen_handler: Any = None
        self.screen_formatter: Any = None
        self.file_formatter: Any = None
        self._log_handler_factory: Any = None
        logging.root.setLevel(logging.INFO)
        self.set_screen_format("default")
        self.set_log_format("default")

    @property
    def level(self) -> int:
        return logging.root.getEffectiveLevel()

    @level.setter
    def level(self, new_level: int) -> None:
        logging.root.setLevel(new_level)

    @property
    def log_dir(self) -> str:
        """The run's log folder, made on first use (with a ``latest`` link next to it)."""
        if self._log_dir is None:
            self._log_dir = _make_unique_log_dir(base_path=_get_logging_directory())
            try:
                if not _renew_latest_log_dir(log_dir=self._log_dir):
                    warnings.warn("Cannot create a symlink to latest log directory", stacklevel=2)
            except OSError as e:
                warnings.warn(
                    f"Cannot create a symlink to latest log directory: {e}\n", stacklevel=2
                )
        return self._log_dir

    @log_dir.setter
    def log_dir(self, new_log_dir: str | None) -> None:
        if new_log_dir is not None:
            if self.file_handlers:
                warnings.warn(
                    f"Loggers have been already configured to output to log files below"
                    f" {self._log_dir}. Proceed at your own risk.",
                    stacklevel=2,
                )
            if not os.path.isdir(new_log_dir):
                raise ValueError(f"{new_log_dir} is not a directory")
        self._log_dir = new_log_dir

    @property
    def log_handler_factory(self) -> Any:
        if self._log_handler_factory is None:
            self._log_handler_factory = handlers.WatchedFileHandler  # type: ignore[attr-defined]
        return self._log_handler_factory

    @log_handler_factory.setter
    def log_handler_factory(self, factory: Any) -> None:
        self._log_handler_factory = factory

    def set_screen_format(self, screen_format: str | None, *, screen_style: str | None = None):  # type: ignore[no-untyped-def]
        """The screen format: a logging format, 'default' or 'default_with_timestamp'
        (OVERRIDE_LAUNCH_SCREEN_FORMAT wins)."""
        self.screen_formatter = _formatter(
            screen_format, screen_style, "OVERRIDE_LAUNCH_SCREEN_FORMAT", "screen"
        )
        if self.screen_handler is not None and self.screen_formatter is not None:
            self.screen_handler.setFormatter(self.screen_formatter)

    def get_screen_handler(self) -> Any:
        """The one screen handler (stdout)."""
        if self.screen_handler is None:
            self.screen_handler = handlers.StreamHandler(sys.stdout)  # type: ignore[attr-defined]
            self.screen_handler.setFormatter(self.screen_formatter)
        return self.screen_handler

    def set_log_format(self, log_format: str | None, *, log_style: str | None = None):  # type: ignore[no-untyped-def]
        """The log-file format: a logging format or 'default' (OVERRIDE_LAUNCH_LOG_FORMAT wins)."""
        self.file_formatter = _formatter(log_format, log_style, "OVERRIDE_LAUNCH_LOG_FORMAT", "log")
        for handler in self.file_handlers.values():
            handler.setFormatter(self.file_formatter)

    def get_log_file_path(self, file_name: str = "launch.log") -> str:
        return os.path.join(self.log_dir, file_name)

    def get_log_file_handler(self, file_name: str = "launch.log") -> Any:
        """The handler of one log file in the log folder (made once)."""
        if file_name not in self.file_handlers:
            handler = self.log_handler_factory(self.get_log_file_path(file_name), encoding="utf-8")
            handler.setFormatter(self.file_formatter)
            self.file_handlers[file_name] = handler
        return self.file_handlers[file_name]


launch_config = LaunchConfig()


def log_launch_config(*, logger: logging.Logger = logging.root) -> None:
    """Say where the log files are and the default verbosity, as launch does at start."""
    if launch_config.file_handlers:
        logger.info(f"All log files can be found below {launch_config.log_dir}")
    level = logging.getLevelName(logging.root.getEffectiveLevel())
    logger.info(f"Default logging verbosity is set to {level}")


def _attach(logger: logging.Logger, handler: Any) -> None:
    if handler not in logger.handlers:
        logger.addHandler(handler)


def get_logger(name: str | None = None) -> logging.Logger:
    """The named logger, writing to the screen and to the launch log file."""
    logger = logging.getLogger(name)
    _attach(logger, launch_config.get_screen_handler())
    _attach(logger, launch_config.get_log_file_handler())
    return logger


# What each alias of ``output=`` sends where: source -> destinations.
_OUTPUT_ALIASES: dict[str, dict[str, set[str]]] = {
    "screen": {"both": {"screen"}},
    "log": {"both": {"log"}, "stderr": {"screen"}},
    "both": {"both": {"log", "screen"}},
    "own_log": {"both": {"own_log"}, "stdout": {"own_log"}, "stderr": {"own_log"}},
    "full": {"both": {"screen", "log", "own_log"}, "stdout": {"own_log"}, "stderr": {"own_log"}},
}


def _normalize_output_configuration(config: Any) -> dict[str, set[str]]:
    normalized: dict[str, set[str]] = {"both": set(), "stdout": set(), "stderr": set()}
    if isinstance(config, str):
        if config not in _OUTPUT_ALIASES:
            raise ValueError(
                f'{config} is not a valid standard output config i.e. "screen", "log" or "both"'
            )
        normalized.update({k: set(v) for k, v in _OUTPUT_ALIASES[config].items()})
        return normalized
    if not isinstance(config, dict):
        raise ValueError(f"{config} is not a valid output configuration")
    for source, destinations in config.items():
        if source not in normalized:
            raise ValueError(
                f'{source} is not a valid output source i.e. "stdout", "stderr" or "both"'
            )
        wanted = {destinations} if isinstance(destinations, str) else set(destinations)
        for destination in wanted - {"screen", "log", "own_log"}:
            raise ValueError(
                f'{destination} is not a valid output destination i.e. "screen", "log" or "own_log"'
            )
        normalized[source] = wanted
    return normalized


def get_output_loggers(process_name: str, output_config: Any) -> tuple[Any, Any]:
    """The (stdout, stderr) loggers of a process for ``output=`` (an alias or a dict of
    source -> destinations; own logs are NAME-stdout.log, NAME-stderr.log and NAME.log)."""
    config = _normalize_output_configuration(output_config)
    for source in ("stdout", "stderr"):
        logger = logging.getLogger(f"{process_name}-{source}")
        wanted = config["both"] | config[source]
        if "screen" in wanted:
            screen = launch_config.get_screen_handler()
            if screen not in logger.handlers:
                screen.setFormatterFor(logger, logging.Formatter("{msg}", style="{"))
                logger.addHandler(screen)
        if "log" in wanted:
            main_log = launch_config.get_log_file_handler()
            if main_log not in logger.handlers:
                main_log.setFormatterFor(
                    logger, logging.Formatter("{created:.7f} {msg}", style="{")
                )
                logger.addHandler(main_log)
        if "own_log" in config[source]:
            own = launch_config.get_log_file_handler(f"{process_name}-{source}.log")
            own.setFormatter(logging.Formatter(fmt=None))
            _attach(logger, own)
        if "own_log" in config["both"]:
            combined = launch_config.get_log_file_handler(f"{process_name}.log")
            combined.setFormatter(logging.Formatter("{msg}", style="{"))
            _attach(logger, combined)
    return logging.getLogger(f"{process_name}-stdout"), logging.getLogger(f"{process_name}-stderr")


class LaunchLogger(logging.getLoggerClass()):  # type: ignore[misc]
    """A logger launch made: it does not propagate, and ``reset()`` clears it."""

    all_loggers: list[logging.Logger] = []

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.propagate = False
        LaunchLogger.all_loggers.append(self)


def reset() -> None:
    """Every launch logger back to no level and no handlers; the configuration afresh."""
    for logger in LaunchLogger.all_loggers:
        logger.setLevel(logging.NOTSET)
        del logger.handlers[:]
    launch_config.reset()
    logging.setLoggerClass(LaunchLogger)


reset()
