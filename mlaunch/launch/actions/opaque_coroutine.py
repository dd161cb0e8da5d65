"""``launch.actions.opaque_coroutine``, where upstream defines it."""

from mlaunch.launch.actions import OpaqueCoroutine

__all__ = ["OpaqueCoroutine"]
