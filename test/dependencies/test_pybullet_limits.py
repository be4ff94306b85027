"""What PyBullet does at the limits the URDF parser enforces: the facts its checks are built on.

Each case runs PyBullet in a child process of its own, so that one which
crashes PyBullet is a result to compare, not a dead test runner.  The robot
is loaded as the simulator loads it (fixed base, the URDF's inertia).  A
failure here means PyBullet changed, and the limit in
pan_tilt_sim/model/urdf.py may have moved with it.
"""

from __future__ import annotations

import json
import pathlib
import signal
import subprocess
import sys
import textwrap

import pytest

from pan_tilt_sim.model.urdf import MAX_MASS, MAX_NAME_BYTES
from pan_tilt_sim.sim.bullet import pybullet

CHILD_BUDGET_S = 60.0
# What each child does first: connect, gravity, load the robot in argv[1] as the simulator does.
PREAMBLE = """
import json, math, sys
import pybullet as p
client = p.connect(p.DIRECT)
p.setGravity(0, 0, -9.81, physicsClientId=client)
p.setTimeStep(0.001, physicsClientId=client)
def load(path, fixed=True, position=(0, 0, 0)):
    return p.loadURDF(path, position, useFixedBase=fixed, flags=p.URDF_USE_INERTIA_FROM_FILE,
                      physicsClientId=client)
def report(**values):
    print(chr(10) + 'RESULT ' + json.dumps(values), flush=True)  # after PyBullet's last line
"""


def link(name, mass='1', inertia='0.01', com='0 0 0'):
    return (f'<link name="{name}"><inertial><origin xyz="{com}"/><mass value="{mass}"/>'
            f'<inertia ixx="{inertia}" ixy="0" ixz="0" iyy="{inertia}" iyz="0" '
            f'izz="{inertia}"/></inertial></link>')


def joint(name, parent, child, kind='revolute', axis='0 0 1'):
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><axis xyz="{axis}"/>'
            '<limit lower="-3" upper="3" effort="10" velocity="1"/></joint>')


def robot(*parts, name='r'):
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n' + '\n'.join(parts) + '\n</robot>\n'


def pendulum(axis='0 1 0', kind='revolute', mass='1'):
    """A link whose centre of mass is 0.1 m out along x, on a joint about ``axis``."""
    return robot(link('a'), link('b', mass=mass, com='0.1 0 0'), joint('j', 'a', 'b', kind, axis))


def run_child(tmp_path: pathlib.Path, urdf: str, body: str) -> subprocess.CompletedProcess:
    """Run PREAMBLE + ``body`` in a fresh Python with ``urdf`` written to a file (argv[1])."""
    path = tmp_path / 'robot.urdf'
    path.write_text(urdf, encoding='utf-8')
    script = PREAMBLE + textwrap.dedent(body)
    return subprocess.run([sys.executable, '-c', script, str(path)], capture_output=True,
                          text=True, timeout=CHILD_BUDGET_S, check=False)


def result(child: subprocess.CompletedProcess, *, then_may_crash: bool = False) -> dict:
    """Return what the child reported; fail with its output if it reported nothing.

    The child must have ended normally, unless ``then_may_crash`` (it may die after
    reporting).
    """
    if not then_may_crash:
        assert child.returncode == 0, (child.returncode, child.stdout[-2000:],
                                       child.stderr[-2000:])
    lines = [line for line in child.stdout.splitlines() if line.startswith('RESULT ')]
    assert lines, child.stdout[-2000:]
    return json.loads(lines[-1].removeprefix('RESULT '))


def killed_by_a_signal(child: subprocess.CompletedProcess) -> bool:
    return child.returncode < 0


READ_NAMES = """
body = load(sys.argv[1])
joint = p.getJointInfo(body, 0, physicsClientId=client)
info = p.getBodyInfo(body, physicsClientId=client)
report(joint=joint[1].decode(), link=joint[12].decode(), root=info[0].decode(),
       robot=info[1].decode())
"""


# --- names ---------------------------------------------------------------------------------

def test_names_of_the_longest_length_taken_come_back_whole(tmp_path):
    """Joint, link, root link and robot names of MAX_NAME_BYTES bytes fit PyBullet's buffers."""
    names = {role: letter * MAX_NAME_BYTES for role, letter in
             (('joint', 'j'), ('link', 'l'), ('root', 'r'), ('robot', 'n'))}
    urdf = robot(link(names['root']), link(names['link']),
                 joint(names['joint'], names['root'], names['link']), name=names['robot'])
    assert result(run_child(tmp_path, urdf, READ_NAMES)) == names


def test_a_link_name_one_byte_longer_runs_into_the_joint_name_next_to_it(tmp_path):
    """1024 bytes leave no room for the NUL: PyBullet reads on into the next field."""
    name = 'l' * (MAX_NAME_BYTES + 1)
    got = result(run_child(tmp_path, robot(link('a'), link(name), joint('j', 'a', name)),
                           READ_NAMES))
    assert got['link'] == name + 'j'


def test_a_joint_name_of_2000_bytes_is_not_survived(tmp_path):
    """The length the fuzzing found: the name overruns PyBullet's buffer and the process dies."""
    child = run_child(tmp_path, robot(link('a'), link('b'), joint('j' * 2000, 'a', 'b')),
                      READ_NAMES)
    assert killed_by_a_signal(child), (child.returncode, child.stdout[-300:])


# --- the tree ------------------------------------------------------------------------------

LOAD_AND_LIST = """
body = load(sys.argv[1])
count = p.getNumJoints(body, physicsClientId=client)
report(joints=[p.getJointInfo(body, i, physicsClientId=client)[1].decode()
               for i in range(count)])
"""


@pytest.mark.parametrize('urdf', [
    pytest.param(robot(link('a'), link('b'), link('c'), joint('j1', 'a', 'b'),
                       joint('j2', 'a', 'c'), joint('j3', 'b', 'c')), id='two joints, one child'),
    pytest.param(robot(link('a'), link('b'), link('c'), joint('j1', 'a', 'b'),
                       joint('j2', 'b', 'c'), joint('j3', 'c', 'b')), id='a cycle off the root'),
    pytest.param(robot(link('a'), link('b'), joint('j1', 'a', 'b'), joint('j2', 'b', 'b')),
                 id='a joint whose parent is its child'),
    pytest.param(robot(link('a'), link('b'), link('c'), joint('j1', 'a', 'b'),
                       joint('j1', 'b', 'c')), id='the same joint name twice'),
])
def test_pybullet_crashes_on_a_description_that_is_no_tree(tmp_path, urdf):
    child = run_child(tmp_path, urdf, LOAD_AND_LIST)
    assert child.returncode == -signal.SIGSEGV, (child.returncode, child.stdout[-300:])


def test_pybullet_silently_drops_a_cycle_that_hangs_off_nothing(tmp_path):
    """The robot loads without the cycle's links and joints: a robot other than the one given."""
    urdf = robot(link('a'), link('b'), link('c'), link('d'), joint('j1', 'a', 'b'),
                 joint('j2', 'c', 'd'), joint('j3', 'd', 'c'))
    assert result(run_child(tmp_path, urdf, LOAD_AND_LIST)) == {'joints': ['j1']}


def test_pybullet_loads_an_orphan_alone_beside_a_cycle_through_the_root_and_may_then_die(
        tmp_path):
    """The cycle is dropped, and what is left of it in PyBullet's memory can kill the process.

    When depends on the heap's layout: a build with NumPy support (upstream's
    wheels, ours built from source) has reported by then; pybullet-arm64's
    wheels, built without it, can die before reporting, as the length of the
    file's path decides.
    """
    urdf = robot(link('a'), link('b'), link('c'), joint('j1', 'a', 'b'), joint('j2', 'b', 'a'))
    child = run_child(tmp_path, urdf, LOAD_AND_LIST)
    assert child.returncode in (0, -signal.SIGSEGV, -signal.SIGABRT)
    if pybullet.isNumpyEnabled() or child.returncode == 0 or 'RESULT ' in child.stdout:
        assert result(child, then_may_crash=True) == {'joints': []}


# --- joint types and axes ------------------------------------------------------------------

SWING = """
body = load(sys.argv[1])
p.setJointMotorControl2(body, 0, p.VELOCITY_CONTROL, force=0, physicsClientId=client)
for _ in range(200):
    p.stepSimulation(physicsClientId=client)
position, velocity = p.getJointState(body, 0, physicsClientId=client)[:2]
tip = p.getLinkState(body, 0, physicsClientId=client)[0]
report(position=position, velocity=velocity, tip=tip, finite=all(
    math.isfinite(v) for v in (position, velocity, *tip)))
"""


def test_pybullet_does_not_normalize_an_axis_a_longer_one_swings_differently(tmp_path):
    """The same pendulum on axis 0 2 0 is somewhere else after 0.2 s than on 0 1 0."""
    unit = result(run_child(tmp_path, pendulum('0 1 0'), SWING))
    longer = result(run_child(tmp_path, pendulum('0 2 0'), SWING))
    assert unit['finite'] and longer['finite']
    assert abs(unit['tip'][0] - longer['tip'][0]) > 0.01


def test_pybullet_reports_a_prismatic_position_in_units_of_the_axis_length(tmp_path):
    unit = result(run_child(tmp_path, pendulum('0 0 1', 'prismatic'), SWING))
    double = result(run_child(tmp_path, pendulum('0 0 2', 'prismatic'), SWING))
    assert double['tip'] == pytest.approx(unit['tip'])  # the link falls the same way ...
    assert double['position'] == pytest.approx(unit['position'] / 2)  # ... half the units


@pytest.mark.parametrize('axis', ['0 0 0', '0 1e-300 0'])
def test_an_axis_without_length_makes_the_state_nan_at_once(tmp_path, axis):
    assert not result(run_child(tmp_path, pendulum(axis), SWING))['finite']


MASS_MATRIX = """
body = load(sys.argv[1])
kind = p.getJointInfo(body, 0, physicsClientId=client)[2]
try:
    p.calculateMassMatrix(body, [0.0], physicsClientId=client)
    failure = ''
except Exception as err:
    failure = type(err).__name__
report(kind=kind, mass_matrix_failure=failure)
"""


def test_pybullet_simulates_a_planar_joint_its_mass_matrix_does_not_know(tmp_path):
    got = result(run_child(tmp_path, pendulum('0 0 1', 'planar'), MASS_MATRIX))
    assert got == {'kind': 3, 'mass_matrix_failure': 'SystemError'}  # 3: JOINT_PLANAR


def test_pybullet_makes_a_floating_joint_fixed(tmp_path):
    got = result(run_child(tmp_path, pendulum('0 0 1', 'floating'), MASS_MATRIX))
    assert got['kind'] == 4  # JOINT_FIXED


# --- masses and inertias -------------------------------------------------------------------

def test_a_negative_mass_breaks_pybullets_mass_matrix(tmp_path):
    got = result(run_child(tmp_path, pendulum(mass='-1'), MASS_MATRIX))
    assert got['mass_matrix_failure'] == 'SystemError'


def test_gravity_on_a_mass_near_the_largest_double_overflows(tmp_path):
    assert not result(run_child(tmp_path, pendulum(mass='1e308'), SWING))['finite']


DROP = """
plane = p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client),
                          physicsClientId=client)
body = load(sys.argv[1], fixed=False, position=(0, 0, 0.2))
for _ in range(1000):
    p.stepSimulation(physicsClientId=client)
report(z=p.getBasePositionAndOrientation(body, physicsClientId=client)[0][2])
"""


def box(mass: float) -> str:
    """A 0.1 m cube of ``mass`` with its solid-cube inertia."""
    inertia = mass * 0.1 ** 2 / 6
    return robot(f'<link name="box"><inertial><mass value="{mass!r}"/><inertia ixx="{inertia!r}" '
                 f'ixy="0" ixz="0" iyy="{inertia!r}" iyz="0" izz="{inertia!r}"/></inertial>'
                 '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>')


def test_the_ground_holds_the_heaviest_mass_taken_and_not_one_a_million_times_heavier(tmp_path):
    resting = result(run_child(tmp_path, box(MAX_MASS), DROP))['z']
    assert resting == pytest.approx(0.05, abs=2e-3)  # the cube's centre, on the ground
    sunk = result(run_child(tmp_path, box(MAX_MASS * 1e6), DROP))['z']
    assert sunk < 0.0


def test_an_inertia_no_rigid_body_has_is_set_to_zero_with_a_warning(tmp_path):
    body = """
    body = load(sys.argv[1])
    report(inertia=p.getDynamicsInfo(body, 0, physicsClientId=client)[2])
    """
    child = run_child(tmp_path, robot(link('a'), link('b', inertia='-0.01'), joint('j', 'a', 'b')),
                      body)
    assert result(child) == {'inertia': [0.0, 0.0, 0.0]}
    assert 'Bad inertia tensor properties, setting inertia to zero' in child.stdout


def test_a_ray_batch_answers_at_most_16383_rays_and_takes_no_more_than_16384(client):
    import pybullet

    from pan_tilt_sim.sim.sensors.lidar import MAX_BATCH

    def cast(count: int) -> int:
        return len(pybullet.rayTestBatch([[0.0, 0.0, 0.0]] * count, [[1.0, 0.0, 0.0]] * count,
                                         physicsClientId=client))

    assert cast(MAX_BATCH) == MAX_BATCH == 16383
    assert cast(MAX_BATCH + 1) == MAX_BATCH  # one ray taken and never answered
    with pytest.raises(pybullet.error, match='exceed the maximum batch size'):
        cast(MAX_BATCH + 2)
