"""The viewer stand-in's inputs: rviz2's command line, its display config, and its port.

What the page draws comes from an .rviz file as rviz2 would read it: the fixed frame and the
topics of the first enabled LaserScan, Odometry, RobotModel and Image (or DepthCloud) displays.
Pure Python; yaml is imported only when a config file is read.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from mlaunch.plan.errors import StandinError

PORT_ENV = "MLAUNCH_VIEWER_PORT"


class ViewerError(StandinError, ValueError):
    """Unusable viewer input (port, command line); printed as one line, exit status 1."""


# ---------------------------------------------------------------- command line and config


@dataclass(frozen=True)
class DisplayConfig:
    """What the viewer takes from an .rviz file: the fixed frame and the topics it draws."""

    fixed_frame: str = "odom"
    scan_topic: str = "scan"
    odom_topic: str = "odom"
    description_topic: str = "robot_description"
    depth_topic: str = ""  # an Image or DepthCloud display's topic: drawn beside the map
    warnings: tuple[str, ...] = ()


def parse_args(args: Sequence[str]) -> argparse.Namespace:
    """rviz2's options (ROS arguments removed); the GUI-only ones are accepted and unused."""
    parser = argparse.ArgumentParser(
        prog="rviz2", description="mlaunch stand-in for rviz2: a top-down view in the browser"
    )
    parser.add_argument("-d", "--display-config", metavar="FILE", help="an .rviz config file")
    parser.add_argument("-f", "--fixed-frame", metavar="FRAME", help="frame to draw in")
    parser.add_argument("-s", "--splash-screen", nargs="?", const="", metavar="IMAGE")
    parser.add_argument("-l", "--ogre-log", action="store_true", help="(ignored)")
    parser.add_argument("--fullscreen", action="store_true", help="(ignored)")
    parser.add_argument("--no-stereo", action="store_true", help="(ignored)")
    parser.add_argument("--disable-anti-aliasing", action="store_true", help="(ignored)")
    parser.add_argument("--opengl", metavar="VERSION", help="(ignored)")
    options, unknown = parser.parse_known_args(list(args))
    if unknown:
        raise ViewerError(
            f"unknown rviz2 option {unknown[0]!r}; see python -m mlaunch.standins.viewer --help"
        )
    return options


def read_display_config(path: str | None) -> DisplayConfig:
    """The fixed frame and topics of an .rviz file; a missing or broken file gives defaults + a
    warning, as rviz2 starts with its default config then."""
    if not path:
        return DisplayConfig()
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        return DisplayConfig(warnings=(f"display config {path!r} not loaded: {exc.strerror}",))
    import yaml  # only when there is a config to read

    from mlaunch.plan.yamldata import load as load_yaml

    try:
        data = load_yaml(text, path)
    except yaml.YAMLError as exc:
        return DisplayConfig(warnings=(f"display config {path!r} is not valid YAML: {exc}",))
    return config_from_data(data)


def config_from_data(data: Any) -> DisplayConfig:
    """Pick the viewer's settings out of a loaded .rviz document (missing parts keep defaults)."""
    manager = data.get("Visualization Manager") if isinstance(data, dict) else None
    if not isinstance(manager, dict):
        return DisplayConfig(warnings=("display config has no 'Visualization Manager' section",))
    found: dict[str, Any] = {}
    options = manager.get("Global Options")
    if isinstance(options, dict) and isinstance(options.get("Fixed Frame"), str):
        found["fixed_frame"] = options["Fixed Frame"]
    for display in _displays(manager.get("Displays")):
        kind = str(display.get("Class", "")).rsplit("/", 1)[-1]
        if kind == "LaserScan":
            _take(found, "scan_topic", _topic(display.get("Topic")))
        elif kind == "Odometry":
            _take(found, "odom_topic", _topic(display.get("Topic")))
        elif kind == "RobotModel":
            _take(found, "description_topic", _topic(display.get("Description Topic")))
        elif kind in ("Image", "DepthCloud"):
            _take(
                found, "depth_topic", _topic(display.get("Topic") or display.get("Depth Map Topic"))
            )
    return replace(DisplayConfig(), **found)


def _displays(items: Any) -> list[dict[str, Any]]:
    """Enabled displays, flattened out of display groups."""
    result: list[dict[str, Any]] = []
    for item in items if isinstance(items, list) else []:
        if not isinstance(item, dict) or item.get("Enabled", True) is False:
            continue
        result.append(item)
        result.extend(_displays(item.get("Displays")))
    return result


def _topic(value: Any) -> str | None:
    """A display's topic: ``Topic: /scan`` (old files) or ``Topic: {Value: /scan, ...}``."""
    if isinstance(value, dict):
        value = value.get("Value")
    return value if isinstance(value, str) and value else None


def _take(found: dict[str, Any], key: str, value: str | None) -> None:
    if value is not None and key not in found:  # the first enabled display of a kind wins
        found[key] = value


def viewer_port(environ: dict[str, str]) -> int:
    """The port to listen on from MLAUNCH_VIEWER_PORT; 0 (the default) means any free port."""
    text = environ.get(PORT_ENV, "").strip() or "0"
    try:
        port = int(text)
    except ValueError:
        port = -1
    if not 0 <= port <= 65535:
        raise ViewerError(f"{PORT_ENV}={text!r} is not a port; use 0..65535 (0 = any free port)")
    return port


# The launch panel (mlaunch.parts.dashboard) of the run a viewer belongs to is reached at this
# abstract unix socket, named after the run id every process of the run has in its environment.
RUN_ID_ENV = "MLAUNCH_RUN_ID"


def dashboard_socket(run_id: str) -> str:
    """The abstract unix socket name (a leading NUL) of run ``run_id``'s launch panel."""
    return f"\0mlaunch-dashboard-{run_id}"
