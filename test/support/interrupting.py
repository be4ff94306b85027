"""SIGINT landing between a stand-in's ``rclpy.ok()`` check and its next wait, made certain.

rclpy's signal handler shuts the context down from its own thread, and without the
context's Python on-shutdown callbacks; so it can land right after a program saw the
context ok.  :func:`interrupted_after_check` runs a call in a fresh Python process (the
default context and rclpy's global executor, as the stand-in programs use them) whose
context shuts down that way right after the first ``ok()`` that answers True once
``armed`` holds (a Python expression, evaluated in the program after ``setup``).
"""

from __future__ import annotations

import subprocess
import sys

PROGRAM = '''
import rclpy

rclpy.init()
node = rclpy.create_node('stand_in')
context = node.context
rclpy.spin_once(node, timeout_sec=0.0)  # rclpy's global executor exists, as in the programs
{setup}
checked = context.ok


def checked_then_interrupted():
    answer = checked()
    if answer and ({armed}):
        context.handle.shutdown()  # what rclpy's SIGINT handler does
    return answer


context.ok = checked_then_interrupted
{call}
print('returned', flush=True)
'''


def interrupted_after_check(imports: str, call: str, setup: str = '',
                            armed: str = 'True') -> subprocess.CompletedProcess:
    """Run ``call`` (on ``node``) in a process whose context is shut down after a True ok()."""
    program = imports + PROGRAM.format(setup=setup, armed=armed, call=call)
    return subprocess.run([sys.executable, '-c', program],
                          capture_output=True, text=True, timeout=60, check=False)
