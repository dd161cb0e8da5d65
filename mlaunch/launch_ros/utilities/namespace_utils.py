"""Namespace helpers of ``launch_ros.utilities`` with upstream's results.

Unlike mlaunch.launch_ros.scope's ``prefix_namespace`` (which the Node planning uses and which
always answers an absolute namespace), this one keeps a relative result relative, as launch_ros.
"""

from __future__ import annotations


def is_namespace_absolute(ns: str) -> bool:
    """Whether ``ns`` starts at the root."""
    return ns.startswith("/")


def is_root_namespace(ns: str) -> bool:
    """Whether ``ns`` is the root namespace itself."""
    return ns == "/"


def prefix_namespace(base_ns: str | None, ns: str | None) -> str | None:
    """``ns`` under ``base_ns`` when ``ns`` is relative, else ``ns``; either alone when the
    other is None; None when both are. Trailing '/' is stripped (but '/' stays '/')."""
    if base_ns is None and ns is None:
        return None
    if ns is None:
        combined = base_ns or ""
    elif not base_ns or is_namespace_absolute(ns):
        combined = ns
    else:
        combined = ("" if is_root_namespace(base_ns) else base_ns) + "/" + ns
    return combined if is_root_namespace(combined) else combined.rstrip("/")


def make_namespace_absolute(ns: str | None) -> str | None:
    """``ns`` with a leading '/' (None stays None)."""
    if ns is None:
        return None
    return ns if is_namespace_absolute(ns) else "/" + ns
