"""The stepping loop's results, pinned to the last bit.

Each scenario drives one robot through a fixed script of commands, in
batches as sim_node runs them, and hashes every JointState sample the
broadcaster takes (sim time, positions, velocities, efforts, as exact
``float.hex`` strings).  The digests are the reference results of the
stepping loop; any change to the per-step
arithmetic -- an operation reordered, a value read a step late -- changes
them.  PyBullet is pinned (3.2.7), so a failure here means the loop changed
what it computes.

Every scenario runs twice: with PyBullet's per-step calls made from C (the
compiled step) and through PyBullet's Python module.
"""

import hashlib

import pytest
from robot_fixtures import JointDef, write_star_robot, write_text

from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory, TrajectoryPoint
from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim import compiled_step
from pan_tilt_sim.sim.engine import make_simulation

BATCHES = (1, 7, 100, 500, 393)  # uneven batches, as the pacer makes them
STEPS = sum(BATCHES) * 3

MIXED_CONTROLLERS = """
jsb:
  type: joint_state_broadcaster/JointStateBroadcaster
  publish_rate: 200
ideal_position:
  type: position_controllers/JointPositionController
  joint: pan
pid_position:
  type: position_controllers/JointPositionController
  joint: tilt
  pid: {p: 40.0, i: 2.0, d: 1.5, i_clamp: 3.0}
ideal_velocity:
  type: velocity_controllers/JointVelocityController
  joint: wheel
pid_velocity:
  type: effort_controllers/JointVelocityController
  joint: roller
effort:
  type: effort_controllers/JointEffortController
  joint: slide
group:
  type: position_controllers/JointGroupPositionController
  joints: [lift, reach]
"""
MIXED_JOINTS = [
    JointDef('pan', damping=0.2, friction=0.1),
    JointDef('tilt', damping=0.0),
    JointDef('wheel', 'continuous', None, None, damping=0.05),
    JointDef('roller', 'continuous', None, None, damping=0.0, friction=0.2),
    JointDef('slide', 'prismatic', -0.2, 0.2),
    JointDef('lift', damping=0.01),
    JointDef('reach', 'prismatic', -0.3, 0.3),
]


@pytest.fixture(autouse=True, params=['compiled', 'python'])
def step_kind(request, monkeypatch):
    """Run the test with the compiled step, then with PyBullet's Python calls."""
    monkeypatch.setenv(compiled_step.ENVIRONMENT_SWITCH, '1' if request.param == 'compiled'
                       else '0')
    return request.param


def recorded_digest(simulation, script) -> str:
    """Run ``script(step)`` before each batch; return the hash of every JointState sample."""
    digest = hashlib.sha256()

    def sink(time, names, positions, velocities, efforts):
        for value in (time, *positions, *velocities, *efforts):
            digest.update(float(value).hex().encode())
        digest.update(b'|'.join(name.encode() for name in names))

    assert simulation.physics.compiled_step == (
        compiled_step.unavailable_reason() == ''), 'the wrong way of stepping'
    for controller in simulation.controllers:
        if hasattr(controller, 'set_sink'):
            controller.set_sink(sink)
    start = simulation.joint_positions()
    for _ in range(3):
        for batch in BATCHES:
            script(simulation.steps)
            simulation.advance(batch)
    assert simulation.steps == STEPS
    moved = [name for name, position in simulation.joint_positions().items()
             if abs(position - start[name]) > 1e-3]
    assert len(moved) >= 2, moved  # the script really drove the robot
    return digest.hexdigest()


def test_the_pan_tilt_example_position_pids():
    share = package_share()
    with make_simulation(str(share / DEFAULT_DESCRIPTION), str(share / DEFAULT_CONTROLLERS),
                         0.001) as simulation:
        def script(step):
            pan = simulation.controller('joint1_position_controller')
            tilt = simulation.controller('joint2_position_controller')
            pan.set_command(1.0 if step < 1500 else -0.5)
            tilt.set_command(-3.0 if step < 2000 else -2.0)
        digest = recorded_digest(simulation, script)
    assert digest == PAN_TILT_DIGEST


def test_the_three_joint_arm_trajectory_gripper_and_mimic():
    share = package_share()
    with make_simulation(str(share / 'urdf' / 'three_joint_arm.xacro'),
                         str(share / 'config' / 'three_joint_arm_controllers.yaml'),
                         0.001) as simulation:
        def script(step):
            if step == 0:
                simulation.controller('arm_controller').set_command(JointTrajectory(
                    ('shoulder_joint', 'extend_joint', 'wrist_joint'),
                    (TrajectoryPoint(0.5, (0.4, 0.05, 1.0), (0.5, 0.0, 1.0)),
                     TrajectoryPoint(1.5, (-0.3, 0.1, 3.0), (0.0, 0.0, 0.0)))))
                simulation.controller('gripper_controller').set_command([0.02])
            if step == 2001:
                simulation.controller('gripper_controller').set_command([0.0])
        digest = recorded_digest(simulation, script)
    assert digest == ARM_DIGEST


def test_every_single_joint_controller_kind_and_a_group(tmp_path):
    urdf = write_star_robot(tmp_path, MIXED_JOINTS, name='mixed')
    config = write_text(tmp_path, 'mixed.yaml', MIXED_CONTROLLERS)
    with make_simulation(str(urdf), str(config), 0.001) as simulation:
        commands = {'ideal_position': 0.8, 'pid_position': -0.6, 'ideal_velocity': 1.5,
                    'pid_velocity': -2.0, 'effort': 3.0, 'group': [0.7, 0.15]}

        def script(step):
            sign = 1.0 if step < 1800 else -1.0
            for name, value in commands.items():
                value = [sign * v for v in value] if isinstance(value, list) else sign * value
                simulation.controller(name).set_command(value)
        digest = recorded_digest(simulation, script)
    assert digest == MIXED_DIGEST


PAN_TILT_DIGEST = 'c8cc98baa452f46fe6a442e0a5648e119d7b3aa652c975fe920c942284d7bd20'
ARM_DIGEST = '71b27e2d70bd5f46382d29249316bffb303c084dda4436d89485f14bc776d795'
MIXED_DIGEST = 'f5105e2056e5fd11a00048ac96c7d2d06fd33f30cdfbe51c260c440c5423e650'
