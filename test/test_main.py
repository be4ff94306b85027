"""The sim_node program's entry module (``python -m pan_tilt_sim``)."""

from __future__ import annotations

import os
import subprocess
import sys

PROBE = ("import os, sys; import pan_tilt_sim.__main__; "
         "print(os.environ.get('OPENBLAS_NUM_THREADS'), 'numpy' in sys.modules)")


def run_probe(**env: str) -> str:
    environment = {k: v for k, v in os.environ.items() if k != 'OPENBLAS_NUM_THREADS'}
    environment.update(env)
    return subprocess.run([sys.executable, '-P', '-c', PROBE], env=environment, check=True,
                          capture_output=True, text=True, timeout=60).stdout.strip()


def test_openblas_is_single_threaded_before_numpy_is_imported() -> None:
    assert run_probe() == '1 False'


def test_a_users_openblas_setting_wins() -> None:
    assert run_probe(OPENBLAS_NUM_THREADS='3') == '3 False'
