"""The one import of PyBullet, with its build banner silenced, and its messages caught.

PyBullet prints its build banner (and its loaders their messages) on the
C-level stdout/stderr, where Python cannot redirect it; users should see
one line, not a banner.  Every module that calls PyBullet takes ``pybullet``
from here, and only the simulation layer does.

What PyBullet says while loading a robot matters, though: "Bad inertia
tensor properties, setting inertia to zero for link: ..." changes the
robot, and "Cannot load URDF file." hides its reason
(``XML_ERROR_PARSING_ATTRIBUTE ...``) in that output.
:func:`captured_native_output` collects it and :func:`message_lines` makes
one line of each message.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import re
import sys
import tempfile
from collections.abc import Iterator

# PyBullet writes ``b3Warning[file,line]:\n<message>`` (also b3Error, b3Printf).
_MESSAGE_HEADER = re.compile(r'b3(?:Warning|Error|Printf)\[[^\]]*\]:\s*\n')
_BANNER_PREFIXES = ('pybullet build time', 'argv[0]=')
# "No inertial data for link, ..." is followed by the link's name as a message of its own.
_NO_INERTIAL = 'No inertial data for link'

try:
    _libc: ctypes.CDLL | None = ctypes.CDLL(None)
except OSError:  # pragma: no cover -- no C library to flush (not on Linux/macOS)
    _libc = None


def _flush_native() -> None:
    """Flush C stdio's buffers (PyBullet's printf output may sit in them)."""
    if _libc is not None:
        _libc.fflush(None)


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
        _flush_native()
        for fd, copy in saved:
            os.dup2(copy, fd)
            os.close(copy)


@contextlib.contextmanager
def captured_native_output(sink: list[str]) -> Iterator[None]:
    """Collect C-level stdout/stderr written inside the block; append it to ``sink``."""
    sys.stdout.flush()
    sys.stderr.flush()
    _flush_native()
    with tempfile.TemporaryFile() as capture:
        saved = []
        try:
            for fd in (1, 2):
                saved.append((fd, os.dup(fd)))
                os.dup2(capture.fileno(), fd)
            yield
        finally:
            _flush_native()  # before the fds go back, or the text leaks out later
            for fd, copy in saved:
                os.dup2(copy, fd)
                os.close(copy)
            capture.seek(0)
            sink.append(capture.read().decode('utf-8', 'replace'))


def message_lines(text: str) -> list[str]:
    """Return one line per distinct PyBullet message in ``text`` (banner and repeats dropped)."""
    parts = [line.strip() for chunk in _MESSAGE_HEADER.split(text)
             for line in chunk.splitlines() if line.strip()]
    lines: list[str] = []
    index = 0
    while index < len(parts):
        part = parts[index]
        index += 1
        if part.startswith(_BANNER_PREFIXES):
            continue
        if part.startswith(_NO_INERTIAL) and index < len(parts):
            part = f"link '{parts[index]}': {part}"
            index += 1
        if part not in lines:
            lines.append(part)
    return lines


with quiet_native_output():
    import pybullet  # noqa: E402

__all__ = ['captured_native_output', 'message_lines', 'pybullet', 'quiet_native_output']
