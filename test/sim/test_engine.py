"""The simulation loop with the seed's robot, no ROS: the behaviour Gazebo users expect."""

import pytest

from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import ControllersConfig, ControllerSpec
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.sim.engine import Simulation, make_simulation

DT = 0.001
STEPS_PER_SECOND = 1000


@pytest.fixture
def pan_tilt(repo_root):
    simulation = make_simulation(str(repo_root / 'urdf' / 'pan_tilt.xacro'),
                                 str(repo_root / 'config' / 'pan_tilt_control.yaml'), DT)
    yield simulation
    simulation.close()


def _config(tmp_path, *controllers):
    return ControllersConfig(tuple(ControllerSpec(name, spec['type'], spec)
                                   for name, spec in controllers), tmp_path / 'c.yaml')


def test_joints_start_at_zero_or_their_nearest_limit(pan_tilt):
    assert pan_tilt.joint_positions() == {'pan_joint': 0.0, 'tilt_joint': -1.570796}


def test_without_commands_the_joints_hold_still(pan_tilt):
    pan_tilt.advance(2 * STEPS_PER_SECOND)
    positions = pan_tilt.joint_positions()
    assert positions['pan_joint'] == pytest.approx(0.0, abs=1e-3)
    assert positions['tilt_joint'] == pytest.approx(-1.570796, abs=1e-3)


def test_reset_puts_joints_time_and_setpoints_back(pan_tilt):
    pan_tilt.controller('joint1_position_controller').set_command(1.0)
    pan_tilt.advance(3 * STEPS_PER_SECOND)
    pan_tilt.reset()
    assert pan_tilt.time == 0.0
    assert pan_tilt.joint_positions() == {'pan_joint': 0.0, 'tilt_joint': -1.570796}
    pan_tilt.advance(STEPS_PER_SECOND)
    assert pan_tilt.joint_positions()['pan_joint'] == pytest.approx(0.0, abs=1e-3)


def test_damping_and_coulomb_friction_set_the_steady_speed(repo_root, tmp_path):
    description = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    config = _config(tmp_path, ('pan_effort', {
        'type': 'effort_controllers/JointEffortController', 'joint': 'pan_joint'}))
    with Simulation(description, config, DT) as simulation:
        simulation.controller('pan_effort').set_command(50.0)
        simulation.advance(STEPS_PER_SECOND)
        # (50 N*m - 1 N*m friction) / 50 N*m*s/rad damping
        assert simulation.joint_velocities()['pan_joint'] == pytest.approx(0.98, abs=0.01)


def test_a_velocity_controller_tracks_its_command(repo_root, tmp_path):
    description = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    config = _config(tmp_path, ('pan_velocity', {
        'type': 'effort_controllers/JointVelocityController', 'joint': 'pan_joint',
        'pid': {'p': 200.0, 'i': 2000.0}}))
    with Simulation(description, config, DT) as simulation:
        simulation.controller('pan_velocity').set_command(0.05)
        simulation.advance(2 * STEPS_PER_SECOND)
        assert simulation.joint_velocities()['pan_joint'] == pytest.approx(0.05, abs=0.005)


def test_unknown_controller_types_list_the_supported_ones(repo_root, tmp_path):
    description = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    config = _config(tmp_path, ('x', {'type': 'fancy/Controller', 'joint': 'pan_joint'}))
    with pytest.raises(ControllerConfigError,
                       match=r"x.type: unknown controller type 'fancy/Controller', and no "
                             r'other controller in the file commands a joint '
                             r'\(supported: .*position_controllers/JointPositionController'):
        Simulation(description, config, DT)


def test_a_joint_not_in_the_urdf_lists_the_joints_that_exist(repo_root, tmp_path):
    description = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    config = _config(tmp_path, ('x', {'type': 'effort_controllers/JointEffortController',
                                      'joint': 'roll_joint'}))
    with pytest.raises(ControllerConfigError, match='pan_joint, tilt_joint'):
        Simulation(description, config, DT)


def test_a_joint_claimed_by_two_controllers_is_refused(repo_root, tmp_path):
    description = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    effort = {'type': 'effort_controllers/JointEffortController', 'joint': 'pan_joint'}
    config = _config(tmp_path, ('a', effort), ('b', effort))
    with pytest.raises(ControllerConfigError, match="'pan_joint' is claimed by both 'a' and 'b'"):
        Simulation(description, config, DT)
