"""``CtlError``: what ``mlaunch ctl`` raises, and its trust checks (mlaunch.commands.ctl_trust)
too, when it cannot reach a run or the run refused."""

from __future__ import annotations

from mlaunch.plan.errors import EXIT_FAILURE, MlaunchError


class CtlError(MlaunchError):
    """``mlaunch ctl`` cannot reach the run or the run refused; ``exit_code`` from the table."""

    def __init__(self, message: str, exit_code: int = EXIT_FAILURE) -> None:
        super().__init__(message)
        self.exit_code = exit_code
