"""Frame ids as tf2 and rcl take them: what a controller or plugin may publish. No ROS.

tf2 refuses an empty frame id and strips one leading '/'; rcl's names are
letters, digits and underscores in tokens separated by one '/'.  URDF link
names -- which become frame ids through robot_state_publisher -- also use
'-' and '.', so those are taken too; a token of only '.' or '..' is not.
"""

from __future__ import annotations

import re

# A frame id's token: what tf2 and robot_state_publisher take from URDF link names
# (rcl's name characters, plus '-' and '.').  Tokens are separated by one '/'.
_FRAME_TOKEN = re.compile(r'[A-Za-z0-9_.\-]+')
FRAME_ID_RULE = ("letters, digits, '_', '-' and '.', in tokens separated by one '/' (no "
                 "empty, '.' or '..' token, no spaces)")


def frame_id_problem(value: str) -> str | None:
    """Return what makes ``value`` no valid frame id, or None (tf2 strips one leading '/')."""
    name = value.removeprefix('/')
    if not name:
        return f'{value!r} is not a frame id: it is empty'
    for token in name.split('/'):
        if not _FRAME_TOKEN.fullmatch(token) or token in ('.', '..'):
            return f'{value!r} is not a valid frame id ({FRAME_ID_RULE})'
    return None
