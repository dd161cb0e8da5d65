"""Where a launch file stops being UTF-8 text: one located error instead of a codec message."""

from __future__ import annotations

from mlaunch.plan.errors import LaunchFileError


def not_utf8(data: bytes, path: str) -> LaunchFileError | None:
    """The error for ``data`` (the file at ``path``) when it is not UTF-8, else None.

    Called on the error path of a parser only, so a valid file costs nothing; the line and
    column count bytes up to the first bad one.
    """
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as e:
        line_start = data.rfind(b"\n", 0, e.start) + 1
        line = data.count(b"\n", 0, e.start) + 1
        bad = " ".join(f"0x{b:02X}" for b in data[e.start : e.end])
        return LaunchFileError(
            f"the file is not UTF-8 text: byte {bad} ({e.reason}); save it as UTF-8",
            where=f"{path}:{line}:{e.start - line_start + 1}",
        )
    return None
