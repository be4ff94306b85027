"""Waiting for a condition with a budget, for tests whose events happen in other threads."""

from __future__ import annotations

import time
from collections.abc import Callable

BUDGET_S = 10.0
POLL_S = 0.005


def wait_for(condition: Callable[[], object], budget_s: float = BUDGET_S,
             step_s: float = POLL_S) -> bool:
    """Return True as soon as ``condition()`` holds, False once ``budget_s`` has passed."""
    deadline = time.monotonic() + budget_s
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(step_s)
    return True
