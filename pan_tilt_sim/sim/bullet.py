"""The one import of PyBullet, with its build banner silenced.

PyBullet prints its build banner (and its loaders their chatter) on the
C-level stdout/stderr, where Python cannot redirect it; users should see
one line, not a banner.  Every module that calls PyBullet takes ``pybullet``
from here, and only the simulation layer does.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator


@contextlib.contextmanager
def quiet_native_output() -> Iterator[None]:
    """Silence C-level stdout/stderr (PyBullet's build banner and loader chatter)."""
    saved = []
    try:
        with open(os.devnull, 'wb') as devnull:
            for fd in (1, 2):
                saved.append((fd, os.dup(fd)))
                os.dup2(devnull.fileno(), fd)
            yield
    finally:
        for fd, copy in saved:
            os.dup2(copy, fd)
            os.close(copy)


with quiet_native_output():
    import pybullet  # noqa: E402

__all__ = ['pybullet', 'quiet_native_output']
