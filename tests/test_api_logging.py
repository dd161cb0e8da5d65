"""launch.logging as launch offers it to scripts and extensions (issue 25, gap 4)."""

from __future__ import annotations

import logging
import re
from pathlib import Path

import pytest

from mlaunch.launch import logging as launch_logging


@pytest.fixture(autouse=True)
def fresh(monkeypatch: pytest.MonkeyPatch, tmp_path: Path):  # type: ignore[no-untyped-def]
    monkeypatch.delenv("OVERRIDE_LAUNCH_SCREEN_FORMAT", raising=False)
    monkeypatch.delenv("OVERRIDE_LAUNCH_LOG_FORMAT", raising=False)
    launch_logging.reset()
    launch_logging.launch_config.log_dir = str(tmp_path)
    yield
    launch_logging.reset()
    logging.setLoggerClass(logging.Logger)


def test_get_logger_prints_launch_lines_and_logs_them(capsys: pytest.CaptureFixture[str]) -> None:
    logger = launch_logging.get_logger("api-test")
    logger.info("hello")
    launch_logging.launch_config.get_log_file_handler().flush()
    assert capsys.readouterr().out.splitlines() == ["[INFO] [api-test]: hello"]
    text = Path(launch_logging.launch_config.get_log_file_path()).read_text()
    assert re.fullmatch(r"[0-9]+\.[0-9]+ \[INFO\] \[api-test\]: hello\n", text)


def test_output_loggers_route_by_alias(capsys: pytest.CaptureFixture[str]) -> None:
    out, err = launch_logging.get_output_loggers("proc", "own_log")
    out.info("to own log")
    err.info("err line")
    for name in ("proc-stdout.log", "proc-stderr.log", "proc.log"):
        launch_logging.launch_config.get_log_file_handler(name).flush()
    folder = Path(launch_logging.launch_config.log_dir)
    assert (folder / "proc-stdout.log").read_text() == "to own log\n"
    assert (folder / "proc.log").read_text() == "to own log\nerr line\n"
    assert capsys.readouterr().out == ""
    with pytest.raises(ValueError, match="not a valid"):
        launch_logging.get_output_loggers("proc", "nowhere")
    with pytest.raises(ValueError, match="output destination"):
        launch_logging.get_output_loggers("proc", {"stdout": {"garbage"}})


def test_formats_refuse_a_style_with_an_alias() -> None:
    with pytest.raises(ValueError, match="custom format style"):
        launch_logging.launch_config.set_screen_format("default", screen_style="%")
    with pytest.raises(ValueError, match="not a directory"):
        launch_logging.launch_config.log_dir = "not/a/real/dir"
