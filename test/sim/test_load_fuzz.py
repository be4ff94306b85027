"""Fuzzing the load path: any URDF or SDF starts with finite states or is refused in one line.

Whatever description :func:`urdf_strategies.robots` (or, for SDF,
:func:`sdf_strategies.sdf_robots`) draws, starting a
simulation of it (as sim_node does) and spawning it as an object (as
SpawnEntity does) either works -- every joint state and the object's pose
still finite after a few hundred steps -- or ends in a ConfigurationError
(SpawnError for the object) with one line.  Never a crash, a traceback, a
hang or a NaN.

PyBullet segfaults on some inputs, so the examples run in a child process
(test/sim/load_worker.py, run by test/sim/worker_process.py), one after another: a
crash or a hang there is a failing example here, and the next example gets a
fresh child.  CI runs
:data:`EXAMPLES` examples; ``PAN_TILT_SIM_SLOW=1`` runs :data:`SLOW_EXAMPLES`.
"""

from __future__ import annotations

import os
import pathlib
import signal

import pytest
from hypothesis import HealthCheck, event, given, settings
from sdf_strategies import FuzzSdf, sdf_robots
from urdf_strategies import FuzzRobot, robots
from worker_process import WorkerProcess

SLOW_ENV = 'PAN_TILT_SIM_SLOW'
EXAMPLES = 100
SLOW_EXAMPLES = 2000
STEPS = 300  # physics steps each loaded robot and spawned object runs
WORKER = pathlib.Path(__file__).resolve().parent / 'load_worker.py'
ROBOT_OUTCOMES = ('refused', 'loaded')
OBJECT_OUTCOMES = ('refused', 'spawned')


@pytest.fixture(scope='module')
def worker():
    child = WorkerProcess(WORKER)
    yield child
    child.close()


def _examples() -> int:
    return SLOW_EXAMPLES if os.environ.get(SLOW_ENV) else EXAMPLES


# Words of each kind of refusal, for the statistics (--hypothesis-show-statistics).
REFUSALS = ('child of two joints', 'form a cycle', 'both its parent and its child',
            'declared twice', 'bytes long', 'is not simulated', 'has no direction', '<mass',
            '<inertia', 'non-finite position', 'is not a number', 'is not finite',
            'not three numbers', 'unknown type', 'no movable joints', 'PyBullet cannot load',
            'child of no joint', 'not a valid ROS name', 'a controller can only drive')


def _one_line(answer: dict, what: str) -> None:
    message = answer['message']
    assert message and '\n' not in message, message
    kind = next((words for words in REFUSALS if words in message), 'other')
    event(f'{what} refused: {kind}')


@settings(max_examples=_examples(), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(robot=robots())
def test_any_description_loads_with_finite_states_or_is_refused_in_one_line(worker,
                                                                             robot: FuzzRobot):
    answer = worker.run(robot.request(STEPS))
    loaded, spawned = answer['robot'], answer['object']
    event(f"robot: {loaded['outcome']}")
    event(f"object: {spawned['outcome']}")
    assert loaded['outcome'] in ROBOT_OUTCOMES, loaded.get('traceback')
    assert spawned['outcome'] in OBJECT_OUTCOMES, spawned.get('traceback')
    for what, part in (('robot', loaded), ('object', spawned)):
        if part['outcome'] == 'refused':
            _one_line(part, what)
        else:
            assert part['finite'], f'the {what} has a NaN or infinite state'


@settings(max_examples=_examples() // 2, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(robot=sdf_robots())
def test_any_sdf_robot_loads_with_finite_states_or_is_refused_in_one_line(worker,
                                                                          robot: FuzzSdf):
    answer = worker.run(robot.request(STEPS))
    for what, part, outcomes in (('robot', answer['robot'], ROBOT_OUTCOMES),
                                 ('object', answer['object'], OBJECT_OUTCOMES)):
        event(f"{what}: {part['outcome']}")
        assert part['outcome'] in outcomes, part.get('traceback')
        if part['outcome'] == 'refused':
            _one_line(part, what)
        else:
            assert part['finite'], f'the {what} has a NaN or infinite state'


def test_a_worker_that_dies_is_a_failure_and_the_next_request_gets_a_new_one(worker):
    pid = worker.pid
    os.kill(pid, signal.SIGSEGV)
    request = {'urdf': '<robot name="r"><link name="a"/></robot>',
               'controllers': 'jsb: {type: joint_state_broadcaster/JointStateBroadcaster}\n',
               'steps': 1}
    with pytest.raises(pytest.fail.Exception, match='the worker died .killed by SIGSEGV'):
        worker.run(request)
    answer = worker.run(request)
    assert worker.pid != pid
    assert answer['robot']['outcome'] == 'refused'  # no movable joints
    assert 'no movable joints' in answer['robot']['message']
