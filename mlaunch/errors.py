"""One small error hierarchy. Every error knows where it happened; cli.main prints it once."""

from __future__ import annotations


class MlaunchError(Exception):
    """Base of every error mlaunch reports to the user as one line (no traceback without --debug).

    ``where`` is ``file:line`` (or ``file:line:col``) of the launch-file text at fault, ``what``
    names the action, tag or attribute involved. Both are filled in as the error travels up when
    they are not known where it is raised.
    """

    exit_code = 2

    def __init__(self, message: str, *, where: str | None = None, what: str | None = None):
        super().__init__(message)
        self.message = message
        self.where = where
        self.what = what

    def __str__(self) -> str:
        parts = []
        if self.where:
            parts.append(f"{self.where}:")
        if self.what:
            parts.append(f"{self.what}:")
        parts.append(self.message)
        return " ".join(parts)


class LaunchFileError(MlaunchError):
    """The launch file cannot be found, read or parsed (syntax, schema, unknown tags)."""


class SubstitutionFailure(MlaunchError):
    """A substitution cannot be performed (unset configuration, failing command, ...)."""


class InvalidConditionExpressionError(SubstitutionFailure):
    """An if/unless expression is not one of true, false, 1, 0."""


class LaunchArgumentError(MlaunchError):
    """A launch argument is missing, malformed or outside its choices."""


class PackageNotFoundError(MlaunchError):
    """A ROS package or an executable inside one cannot be found."""


class UsageError(MlaunchError):
    """The command line itself is wrong."""
