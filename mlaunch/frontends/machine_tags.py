"""The machine tags of YAML/XML launch files: ``<machine>`` and ``<push-machine>`` (the
``machine=`` attribute of process tags is read with their other attributes).

mlaunch.machines is imported only when such a tag appears.
"""

from __future__ import annotations

from mlaunch.frontends.element import Element
from mlaunch.frontends.fields import Builder, required_text

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any

# The optional attributes of <machine>: ROS 1's dashed spelling, and the Python keyword's.
MACHINE_ATTRIBUTES = {
    "user": ("user",),
    "ssh_port": ("ssh-port", "ssh_port"),
    "env_loader": ("env-loader", "env_loader"),
    "default": ("default",),
    "timeout": ("timeout",),
}


def _machine(e: Element) -> Any:
    """``<machine name address user ssh-port env-loader default timeout/>``."""
    from mlaunch.machines.actions import Machine

    kwargs: dict[str, Any] = {
        "name": required_text(e, "name"),
        "address": required_text(e, "address"),
    }
    for key, spellings in MACHINE_ATTRIBUTES.items():
        for spelling in spellings:
            if not e.has(spelling):
                continue
            if key == "ssh_port":
                kwargs[key] = e.number(spelling, int, minimum=1)
            elif key == "timeout":
                kwargs[key] = e.number(spelling, minimum=0.0)
            else:
                kwargs[key] = e.text(spelling)
            break
    return Machine(**kwargs)


def _push_machine(e: Element) -> Any:
    from mlaunch.machines.actions import PushMachine

    return PushMachine(required_text(e, "name"))


# The machine tags of the tag table (``mlaunch.frontends.tags.ACTIONS``).
MACHINE_TAGS: dict[str, Builder] = {
    "machine": _machine,
    "push-machine": _push_machine,
    "push_machine": _push_machine,
}
