"""Respawn policy: whether a process that exited starts again, and after how long.

Crash loops back off: the first restart waits ``respawn_delay`` (often 0), and each further exit
within STABLE_UPTIME of starting multiplies the wait by ``respawn_backoff``, up to
``respawn_max_delay``. A process that ran well for a while starts over from the first delay.
"""

from __future__ import annotations

from mlaunch.engine.records import ProcessRecord
from mlaunch.plan.steps import RespawnPolicy

# A crash loop's backoff starts over once a process has stayed up this long.
STABLE_UPTIME = 10.0
# With respawn_backoff > 1 but no respawn_delay, the backoff grows from this (0 * 2**n is 0).
BACKOFF_BASE = 0.1

# What next_restart decides besides a delay.
NO_RESTART = -1.0
GIVE_UP = -2.0


def respawn_delay(policy: RespawnPolicy, streak: int) -> float:
    """The wait before the next start: ``delay``, then growing by ``backoff`` per quick exit.

    Capped at ``max_delay`` (or ``delay`` if that is larger).
    """
    if streak <= 0 or policy.backoff <= 1.0:
        return policy.delay
    base = policy.delay or BACKOFF_BASE
    cap = max(policy.max_delay, policy.delay)
    return min(base * policy.backoff ** min(streak, 64), cap)


def next_restart(policy: RespawnPolicy, record: ProcessRecord, code: int, uptime: float) -> float:
    """The delay before restarting a process that exited with ``code`` after ``uptime`` seconds.

    NO_RESTART when the policy does not restart it, GIVE_UP when its retries are spent (restarts
    the user asked for do not count). Updates the record's crash-loop streak (the exponent of
    the backoff).
    """
    if policy.mode == "never" or (policy.mode == "on-failure" and code == 0):
        return NO_RESTART
    if 0 <= policy.max_retries <= record.restarts - record.user_starts:
        return GIVE_UP
    if uptime >= STABLE_UPTIME:
        record.streak = 0  # it ran well for a while: not a crash loop
    delay = respawn_delay(policy, record.streak)
    record.streak += 1
    return delay
