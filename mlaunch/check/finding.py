"""What --check reports: a ``Finding`` (one thing Jazzy would reject or read differently, and
where), and the boolean rule the XML/YAML and the Python checks share (``reads_as_bool``)."""

from __future__ import annotations


class Finding:
    """One thing Jazzy would reject or read differently, and where."""

    __slots__ = ("message", "where")

    def __init__(self, where: str, message: str) -> None:
        self.where = where
        self.message = message

    def __str__(self) -> str:
        return f"{self.where}: {self.message}"

    def __repr__(self) -> str:
        return f"Finding({self.where!r}, {self.message!r})"


def reads_as_bool(text: str) -> bool:
    """Whether ``text`` is a boolean as Jazzy reads it (``1``/``0``, or a YAML boolean)."""
    import yaml

    if text in ("1", "0"):
        return True
    try:
        return isinstance(yaml.safe_load(text), bool)
    except yaml.YAMLError:
        return False
