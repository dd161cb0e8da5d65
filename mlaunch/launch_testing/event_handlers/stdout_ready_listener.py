"""``StdoutReadyListener``: actions to run once a process prints a given text on stdout."""

from __future__ import annotations

from mlaunch.launch.event_handlers.on_process_io import OnProcessIO

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class StdoutReadyListener(OnProcessIO):
    """An OnProcessIO handler for processes that say they are ready by printing a text.

    Each stdout chunk of ``target_action`` (of any process when None) that contains
    ``ready_txt`` runs ``actions`` (typically a ReadyToTest).
    """

    def __init__(self, *, target_action: Any = None, ready_txt: str, actions: list[Any]) -> None:
        self.__ready_txt = ready_txt
        self.__actions = actions
        super().__init__(target_action=target_action, on_stdout=self.__on_stdout)

    def __on_stdout(self, process_io: Any) -> list[Any] | None:
        if self.__ready_txt in process_io.text.decode("utf-8", "replace"):
            return self.__actions
        return None

    def describe(self) -> tuple[str, list[Any]]:
        """(what the handler is, the actions it runs), as launch's introspection reads it."""
        # launch's EventHandler.describe comes with its introspection API; a handler without
        # it is described by its short description.
        parent = getattr(super(), "describe", None)
        head = parent()[0] if parent is not None else self.describe_short()
        return head, self.__actions


__all__ = ["StdoutReadyListener"]
