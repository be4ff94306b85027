"""ros2_control_demos' example 16 on sim_node: diff drive chained into two wheel PIDs.

The rover of test/support/mobile_fixtures.py (velocity command interfaces on both
wheels) with a controllers file in example 16's shape (jazzy's
``diffbot_chained_controllers.yaml``): a broadcaster, one
``pid_controller/PidController`` per wheel (velocity reference and state,
velocity command, example 16's gains) and ``diffbot_base_controller`` whose
wheels are the PIDs' references (``pid_controller_left_wheel_joint/left_wheel_joint``).
Two changes, for the rover and the test: its wheel geometry, and odometry
from the wheels' velocity (``open_loop: false``; example 16 integrates its
commanded twist, which runs ahead of the wheels while the PIDs catch up).
``cmd_vel_timeout`` is 0 because the probe steps the paused node at its own pace.
"""

from __future__ import annotations

import importlib.util
import math

import pytest
import yaml
from geometry_msgs.msg import TwistStamped
from mobile_fixtures import WHEEL_RADIUS, WHEEL_SEPARATION, rover_urdf
from nav_msgs.msg import Odometry
from node_harness import sim_node
from sim_interfaces_client import SimInterfaces, position
from spawner_client import Spawner

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('controller_manager_msgs') is None
    or importlib.util.find_spec('control_msgs') is None,
    reason='controller_manager_msgs or control_msgs is not installed')

TIME_STEP = 0.001
# One update at example 16's update_rate of 10 Hz: the diff drive publishes in its update,
# so its publish_rate of 50 Hz gives a message at every update, as upstream's does.
PERIOD_STEPS = 100
DRIVE = 'diffbot_base_controller'
PIDS = {'left_wheel_joint': 'pid_controller_left_wheel_joint',
        'right_wheel_joint': 'pid_controller_right_wheel_joint'}
SPEED = 0.2  # m/s
WHEEL_SPEED = SPEED / WHEEL_RADIUS  # rad/s each wheel's reference
# Example 16's PI (p 0.5, i 2.5, no feed-forward: jazzy's enable_feedforward is false)
# drives an ideal velocity actuator, so the wheel turns at the PID's output: v = 0.5 e + I
# with dI/dt = 2.5 e.  That leaves no steady-state error while I stays inside its clamp
# (20 rad/s, above the 4 rad/s needed), and the error decays with a time constant of
# 1.5 / 2.5 = 0.6 s of sim time: after the metre's five seconds it is far below 1 %.
TRACKING = 0.01 * WHEEL_SPEED  # rad/s


def example_16_controllers() -> str:
    """Return example 16's controllers file with the rover's geometry (see the module)."""
    gains = {'p': 0.5, 'i': 2.5, 'd': 0.0, 'i_clamp_min': -20.0, 'i_clamp_max': 20.0,
             'antiwindup': True, 'feedforward_gain': 0.95}
    document = {'controller_manager': {'ros__parameters': {
        'update_rate': 10,
        'joint_state_broadcaster': {'type': 'joint_state_broadcaster/JointStateBroadcaster'},
        **{pid: {'type': 'pid_controller/PidController'} for pid in PIDS.values()},
        DRIVE: {'type': 'diff_drive_controller/DiffDriveController'}}}}
    for joint, pid in PIDS.items():
        document[pid] = {'ros__parameters': {
            'dof_names': [joint], 'command_interface': 'velocity',
            'reference_and_state_interfaces': ['velocity'], 'gains': {joint: gains}}}
    document[DRIVE] = {'ros__parameters': {
        'left_wheel_names': [f"{PIDS['left_wheel_joint']}/left_wheel_joint"],
        'right_wheel_names': [f"{PIDS['right_wheel_joint']}/right_wheel_joint"],
        'wheel_separation': WHEEL_SEPARATION, 'wheel_radius': WHEEL_RADIUS,
        'position_feedback': False, 'open_loop': False, 'enable_odom_tf': True,
        'publish_rate': 50.0, 'cmd_vel_timeout': 0.0,
        'linear.x.max_velocity': 1.0, 'linear.x.min_velocity': -1.0,
        'linear.x.max_acceleration': 1.0,
        'angular.z.max_velocity': 1.0, 'angular.z.min_velocity': -1.0,
        'angular.z.max_acceleration': 1.0, 'angular.z.min_acceleration': -1.0}}
    return yaml.safe_dump(document, sort_keys=False)


@pytest.fixture
def chained_rover(tmp_path):
    """The rover on sim_node, paused, its four controllers active as the file declares them."""
    description = tmp_path / 'rover.urdf'
    description.write_text(rover_urdf(), encoding='utf-8')
    controllers = tmp_path / 'diffbot_chained_controllers.yaml'
    controllers.write_text(example_16_controllers(), encoding='utf-8')
    with sim_node(paused=True, time_step=TIME_STEP, robot_description_file=str(description),
                  controllers_file=str(controllers), world='ground') as sim:
        yield sim


def test_list_controllers_shows_the_diff_drive_chained_into_both_wheel_pids(chained_rover):
    listed = Spawner(chained_rover).controllers()
    drive = listed[DRIVE]
    assert drive.state == 'active' and not drive.is_chained
    assert list(drive.claimed_interfaces) == [
        'pid_controller_left_wheel_joint/left_wheel_joint/velocity',
        'pid_controller_right_wheel_joint/right_wheel_joint/velocity']
    assert sorted((c.name, list(c.reference_interfaces)) for c in drive.chain_connections) == [
        ('pid_controller_left_wheel_joint', ['left_wheel_joint/velocity']),
        ('pid_controller_right_wheel_joint', ['right_wheel_joint/velocity'])]
    for joint, pid in PIDS.items():
        assert (listed[pid].state, listed[pid].is_chained) == ('active', True), pid
        assert list(listed[pid].claimed_interfaces) == [f'{joint}/velocity']
        assert list(listed[pid].reference_interfaces) == [f'{joint}/velocity']


def test_cmd_vel_drives_a_metre_the_pids_track_and_odometry_agrees_with_the_truth(
        chained_rover):
    sim = chained_rover
    node = sim.node
    odometry: list[Odometry] = sim.collect(Odometry, f'/{DRIVE}/odom')
    sim.wait_for_subscribers(f'/{DRIVE}/odom')
    command = TwistStamped()
    command.twist.linear.x = SPEED
    sim.command(DRIVE, command)
    while not odometry or odometry[-1].pose.pose.position.x < 1.0:
        count = len(odometry)
        node.step(PERIOD_STEPS)
        assert sim.spin_until(lambda count=count: len(odometry) > count), 'no odometry came'
    simulation = node.simulation
    for joint, pid in PIDS.items():
        # The diff drive wrote the wheel speed into the PID's reference; the PID got it there.
        assert simulation.controller(pid).setpoints()[joint] == pytest.approx(WHEEL_SPEED)
        assert simulation.handles[joint].velocity == pytest.approx(WHEEL_SPEED, abs=TRACKING)
    state = SimInterfaces(sim).entity_state('rover')
    where = position(state)
    travelled = math.hypot(where[0], where[1])
    assert travelled == pytest.approx(1.0, rel=0.05)
    odom = odometry[-1].pose.pose.position
    assert odom.x == pytest.approx(where[0], rel=0.02)
    assert odom.y == pytest.approx(where[1], abs=0.02 * travelled)
