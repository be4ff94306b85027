"""The simulation loop with the pan/tilt example, no ROS: the behaviour Gazebo users expect."""

import pytest
from robot_fixtures import Log, ros2_control_yaml, two_link_arm_urdf, write_text

from pan_tilt_sim.errors import ControllerConfigError, ParameterError
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


# --- where the joints start ----------------------------------------------------------------

INITIAL_VALUES = """<ros2_control name="arm" type="system">
  <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
  <joint name="joint1"><command_interface name="position"/>
    <state_interface name="position"><param name="initial_value">-0.4</param></state_interface>
  </joint>
  <joint name="joint2"><command_interface name="position"/>
    <state_interface name="position"><param name="initial_value">7.0</param></state_interface>
  </joint>
</ros2_control>
</robot>"""


def arm_with_initial_values(tmp_path, initial_positions=None, log=None):
    robot = write_text(tmp_path, 'arm.urdf',
                       two_link_arm_urdf().replace('</robot>', INITIAL_VALUES))
    yaml = write_text(tmp_path, 'c.yaml', ros2_control_yaml({'arm': (
        'position_controllers/JointGroupPositionController', {'joints': ['joint1', 'joint2']})}))
    return make_simulation(str(robot), str(yaml), DT, initial_positions=initial_positions,
                           logger=log)


def test_joints_start_at_the_urdfs_initial_value_clamped_into_their_limits(tmp_path):
    log = Log()
    with arm_with_initial_values(tmp_path, log=log) as sim:
        assert sim.joint_positions() == pytest.approx({'joint1': -0.4, 'joint2': 3.0})
        sim.advance(STEPS_PER_SECOND)  # the ideal actuators hold the start against gravity
        assert sim.joint_positions() == pytest.approx({'joint1': -0.4, 'joint2': 3.0}, abs=1e-3)
    assert "joint 'joint1' starts at -0.4 (<ros2_control> initial_value)" in log.infos
    assert log.warnings == ["joint 'joint2': initial position 7 (<ros2_control> initial_value) "
                            'is outside its limits [-3, 3]; starts at 3']


def test_the_initial_positions_parameter_overrides_and_reset_returns_there(tmp_path):
    with arm_with_initial_values(tmp_path, {'joint2': 0.5}) as sim:
        assert sim.joint_positions() == pytest.approx({'joint1': -0.4, 'joint2': 0.5})
        sim.controller('arm').set_command([1.0, -1.0])
        sim.advance(2 * STEPS_PER_SECOND)
        assert sim.joint_positions()['joint1'] == pytest.approx(1.0, abs=0.005)
        sim.reset(reset_time=False)
        assert sim.joint_positions() == pytest.approx({'joint1': -0.4, 'joint2': 0.5})
        assert sim.controller('arm').setpoints() == pytest.approx({'joint1': -0.4, 'joint2': 0.5})
        sim.advance(STEPS_PER_SECOND)
        assert sim.joint_positions() == pytest.approx({'joint1': -0.4, 'joint2': 0.5}, abs=1e-3)


def test_an_initial_position_for_a_joint_the_robot_lacks_is_refused(tmp_path):
    with pytest.raises(ParameterError, match=r"^parameter 'initial_positions': 'elbow' is not a "
                                             r'movable joint of the robot \(movable joints: '
                                             r'joint1, joint2\)$'):
        arm_with_initial_values(tmp_path, {'elbow': 1.0})


def test_the_start_up_report_waits_for_report_startup(tmp_path, repo_root):
    log = Log()
    description = load_description(repo_root / 'urdf' / 'pan_tilt.xacro')
    config = _config(tmp_path, ('pan_effort', {
        'type': 'effort_controllers/JointEffortController', 'joint': 'pan_joint'}))
    with Simulation(description, config, DT, logger=log) as simulation:
        assert log.infos == []
        simulation.report_startup()
        simulation.report_startup()
    assert log.infos == ["joint 'pan_joint': effort command (pan_effort)",
                         "joint 'tilt_joint': passive: no active controller",
                         "joint 'tilt_joint' starts at -1.5708: 0 is outside its limits "
                         '[-4.71239, -1.5708]']


# --- several robots in one world --------------------------------------------------------


def _plugin_rover(name: str, pose):
    from mobile_fixtures import ROS2_DIFF_DRIVE, rover_urdf

    from pan_tilt_sim.model.base_pose import BasePose
    from pan_tilt_sim.model.controller_config import load_controllers_config
    from pan_tilt_sim.model.description import description_from_text

    description = description_from_text(
        rover_urdf(name, ros2_control=False, extra=f'<gazebo>{ROS2_DIFF_DRIVE}</gazebo>'),
        f'<{name}>')
    return description, load_controllers_config([], {}), BasePose(*pose)


def _forward(simulation: Simulation, speed: float) -> None:
    from pan_tilt_sim.controllers.framework.surface import StampedTwist

    simulation.plugins[0].set_command(StampedTwist(0.0, (speed, 0.0, 0.0), (0.0, 0.0, 0.0)))


def test_a_guest_robot_shares_the_world_steps_with_its_host_and_collides_with_it():
    description, controllers, pose = _plugin_rover('robot1', (0.0, 0.0, 0.0, 0.0))
    with Simulation(description, controllers, 0.001, fixed_base=None,
                    initial_pose=pose) as host:
        description, controllers, pose = _plugin_rover('robot2', (-0.8, 0.0, 0.0, 0.0))
        guest = Simulation(description, controllers, 0.001, fixed_base=None,
                           initial_pose=pose, world=host)
        host.add_guest(guest)
        assert guest.physics.client_id == host.physics.client_id
        _forward(guest, 0.3)
        host.advance(4000)  # 4 s at 0.3 m/s: 1.2 m, through robot1's place if nothing stops it
        assert guest.steps == host.steps == 4000
        (x2, _, _), _ = guest.base_state()
        (x1, _, _), _ = host.base_state()
        assert -0.4 < x2 < x1 - 0.29  # drove up to robot1 (0.3 m long each), never into it
        guest.reset()
        assert guest.base_state()[0][0] == pytest.approx(-0.8, abs=1e-3)


def test_removing_a_guest_takes_its_body_out_and_the_host_runs_on():
    import pybullet

    description, controllers, pose = _plugin_rover('robot1', (0.0, 0.0, 0.0, 0.0))
    with Simulation(description, controllers, 0.001, fixed_base=None,
                    initial_pose=pose) as host:
        client = host.physics.client_id
        bodies = pybullet.getNumBodies(physicsClientId=client)
        description, controllers, pose = _plugin_rover('robot2', (0.0, 1.0, 0.0, 0.0))
        guest = Simulation(description, controllers, 0.001, fixed_base=None,
                           initial_pose=pose, world=host)
        host.add_guest(guest)
        assert pybullet.getNumBodies(physicsClientId=client) == bodies + 1
        host.remove_guest(guest)
        assert pybullet.getNumBodies(physicsClientId=client) == bodies and not host.guests
        _forward(host, 0.3)
        host.advance(1000)
        assert host.base_state()[0][0] > 0.1


def test_removing_the_host_robot_leaves_a_world_that_steps_its_guests_and_takes_new_ones():
    import pybullet

    description, controllers, pose = _plugin_rover('robot1', (0.0, 0.0, 0.0, 0.0))
    with Simulation(description, controllers, 0.001, fixed_base=None,
                    initial_pose=pose) as host:
        client = host.physics.client_id
        description, controllers, pose = _plugin_rover('robot2', (0.0, 1.0, 0.0, 0.0))
        guest = Simulation(description, controllers, 0.001, fixed_base=None,
                           initial_pose=pose, world=host)
        host.add_guest(guest)
        bodies = pybullet.getNumBodies(physicsClientId=client)
        host.advance(10)
        host.remove_robot()
        assert not host.has_robot and guest.has_robot
        assert pybullet.getNumBodies(physicsClientId=client) == bodies - 1
        assert host.plugins == [] and host.controllers == [] and host.joint_positions() == {}
        _forward(guest, 0.3)
        host.advance(1000)
        assert guest.steps == host.steps == 1010  # one clock for the world, robot or not
        assert guest.base_state()[0][0] > 0.1
        host.reset()  # the world back at its start: the guest too
        assert host.steps == guest.steps == 0
        assert guest.base_state()[0][0] == pytest.approx(0.0, abs=1e-3)
        host.remove_guest(guest)  # the world with no robot at all still steps
        host.advance(5)
        assert host.steps == 5
        description, controllers, pose = _plugin_rover('robot3', (1.0, 0.0, 0.0, 0.0))
        later = Simulation(description, controllers, 0.001, fixed_base=None,
                           initial_pose=pose, world=host)
        host.add_guest(later)
        _forward(later, 0.3)
        host.advance(1000)
        assert later.base_state()[0][0] > 1.1
