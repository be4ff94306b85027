"""A free base on the ground: when the base is free, where it starts, and how it meets the ground.

The rover (test/support/mobile_fixtures.py) stands on two wheels and a frictionless
caster; its diff drive controller makes it mobile, so ``fixed_base`` None
(sim_node's ``auto``) frees it.  Driven by the controller's own command, the
wheels' traction moves the base over the ground plane.
"""

from __future__ import annotations

import math

import pytest
from mobile_fixtures import CONTROLLER, REST_HEIGHT, drive_parameters, write_rover
from robot_fixtures import JointDef, Log, ros2_control_yaml, write_star_robot, write_text

from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.model.base_pose import ORIGIN, BasePose
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.entities import Entities
from pan_tilt_sim.sim.physics import BASE_LINK_INDEX

TIME_STEP = 0.001
FRICTION = 1  # index of the lateral friction in pybullet.getDynamicsInfo
STIFFNESS, DAMPING = 9, 8  # ... and of the contact stiffness and damping


def rover(tmp_path, drive=None, *, fixed_base=None, initial_pose=ORIGIN, active=None,
          log=None, **urdf):
    """Return a Simulation of the rover (``fixed_base`` None: auto), logging to ``log``."""
    description, controllers = write_rover(tmp_path, drive, **urdf)
    return make_simulation(str(description), str(controllers), TIME_STEP,
                           fixed_base=fixed_base, initial_pose=initial_pose,
                           active_controllers=active, logger=log)


def drive(simulation, linear: float, angular: float, seconds: float) -> None:
    """Command the twist every step for ``seconds`` of sim time."""
    controller = simulation.controller(CONTROLLER)
    for _ in range(round(seconds / TIME_STEP)):
        controller.set_command(StampedTwist(0.0, (linear, 0.0, 0.0), (0.0, 0.0, angular)))
        simulation.advance(1)


def yaw(rotation) -> float:
    """Return the heading of a quaternion that turns about z only."""
    return 2.0 * math.atan2(rotation[2], rotation[3])


def test_an_active_drive_controller_frees_the_base_resting_on_its_wheels(tmp_path):
    log = Log()
    with rover(tmp_path, log=log) as simulation:
        physics = simulation.physics
        assert not physics.fixed_base
        assert physics.base_frame().translation == pytest.approx((0.0, 0.0, REST_HEIGHT),
                                                                 abs=1e-9)
        simulation.advance(500)  # standing: it neither sinks nor drifts
        assert physics.base_frame().translation == pytest.approx((0.0, 0.0, REST_HEIGHT),
                                                                 abs=1e-4)
        assert any(line.startswith("base: free on the ground (fixed_base is auto and "
                                   "controller 'base_controller'") for line in log.infos)


def test_without_a_drive_controller_or_when_asked_the_base_stays_welded(tmp_path):
    with rover(tmp_path, active=['joint_state_broadcaster']) as simulation:
        assert simulation.physics.fixed_base
    with rover(tmp_path, fixed_base=True) as simulation:
        assert simulation.physics.fixed_base
        drive(simulation, 0.2, 0.0, 0.2)
        assert simulation.physics.base_frame().translation == (0.0, 0.0, 0.0)
        assert simulation.joint_velocities()['left_wheel_joint'] == pytest.approx(4.0, rel=1e-3)


def test_a_robot_hung_on_a_world_link_stays_welded_even_when_asked_to_be_free(tmp_path):
    log = Log()
    with rover(tmp_path, fixed_base=False, world_joint=True, log=log) as simulation:
        assert simulation.physics.fixed_base
    assert any("welded to the world although fixed_base is false: its root link 'world'"
               in line for line in log.warnings)


def test_an_arm_stays_welded_as_before(tmp_path):
    description = write_star_robot(tmp_path, [JointDef('joint1')])
    controllers = write_text(tmp_path, 'arm.yaml', ros2_control_yaml({
        'arm': ('position_controllers/JointGroupPositionController', {'joints': '[joint1]'})}))
    with make_simulation(str(description), str(controllers), TIME_STEP,
                         fixed_base=None) as simulation:
        assert simulation.physics.fixed_base


def test_the_initial_pose_places_the_base_and_lifts_its_lowest_point(tmp_path):
    pose = BasePose(1.0, -2.0, 0.0, math.pi / 2)
    log = Log()
    with rover(tmp_path, initial_pose=pose, log=log) as simulation:
        frame = simulation.physics.base_frame()
        assert frame.translation == pytest.approx((1.0, -2.0, REST_HEIGHT), abs=1e-9)
        assert yaw(frame.rotation) == pytest.approx(math.pi / 2)
    assert any(line.endswith(f'its root link starts at x 1 y -2 z {REST_HEIGHT:.4g} m, '
                             'yaw 1.571 rad') for line in log.infos), log.infos
    with rover(tmp_path, initial_pose=BasePose(z=0.1)) as simulation:
        assert simulation.physics.base_frame().translation[2] == pytest.approx(
            REST_HEIGHT + 0.1)
        simulation.advance(1000)  # it drops onto the ground
        assert simulation.physics.base_frame().translation[2] == pytest.approx(
            REST_HEIGHT, abs=1e-3)


def test_the_start_up_line_names_a_tilted_spawns_roll_and_pitch(tmp_path):
    log = Log()
    with rover(tmp_path, initial_pose=BasePose(roll=0.1, pitch=-0.2, yaw=0.5), log=log):
        pass
    (line,) = [line for line in log.infos if line.startswith('base: free on the ground')]
    assert line.endswith(' m, roll 0.1 pitch -0.2 yaw 0.5 rad'), line


def test_the_wheels_drive_the_base_straight_and_the_odometry_agrees(tmp_path):
    with rover(tmp_path) as simulation:
        drive(simulation, 0.2, 0.0, 5.0)
        drive(simulation, 0.0, 0.0, 0.5)
        x = simulation.physics.base_frame().translation[0]
        odometry = simulation.controller(CONTROLLER).odometry
        assert x == pytest.approx(1.0, rel=0.02)
        assert odometry.x == pytest.approx(x, rel=0.02)


def test_a_base_hung_on_a_massless_footprint_link_drives_too(tmp_path):
    with rover(tmp_path, footprint=True) as simulation:
        assert simulation.physics.base_frame().translation == pytest.approx((0.0, 0.0, 0.0),
                                                                            abs=1e-9)
        drive(simulation, 0.2, 0.0, 2.0)
        frame = simulation.physics.base_frame()
        assert frame.translation[0] == pytest.approx(0.4, rel=0.02)
        assert frame.translation[2] == pytest.approx(0.0, abs=1e-3)  # upright, on the ground


def test_the_wheels_turn_the_base_on_the_spot(tmp_path):
    with rover(tmp_path) as simulation:
        drive(simulation, 0.0, 0.5, math.pi)
        drive(simulation, 0.0, 0.0, 0.5)
        heading = yaw(simulation.physics.base_frame().rotation)
        assert heading == pytest.approx(math.pi / 2, rel=0.02)
        assert simulation.controller(CONTROLLER).odometry.heading == pytest.approx(
            heading, rel=0.02)


def test_a_reset_puts_the_base_back_at_rest_where_it_started(tmp_path):
    with rover(tmp_path, initial_pose=BasePose(0.5, 0.0, 0.0, 0.3)) as simulation:
        start = simulation.physics.base_frame()
        drive(simulation, 0.2, 0.5, 1.0)
        simulation.reset()
        assert simulation.physics.base_frame().translation == pytest.approx(start.translation)
        assert simulation.physics.base_velocity() == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        assert simulation.controller(CONTROLLER).odometry.x == 0.0


def test_friction_and_contact_springs_come_from_the_gazebo_tags_else_gazebo_defaults(tmp_path):
    with rover(tmp_path) as simulation:
        physics = simulation.physics
        client, body = physics.client_id, physics.body_id

        def dynamics(link: str):
            return pybullet.getDynamicsInfo(body, physics.link_index(link),
                                            physicsClientId=client)
        assert dynamics('caster')[FRICTION] == 0.0  # its <mu1>/<mu2> 0
        assert dynamics('left_wheel')[FRICTION] == 1.0  # its tags
        assert dynamics('right_wheel')[FRICTION] == 1.0  # Gazebo's default
        assert pybullet.getDynamicsInfo(physics.ground, BASE_LINK_INDEX,
                                        physicsClientId=client)[FRICTION] == 1.0


def test_a_contact_spring_from_kp_and_kd_is_applied(tmp_path):
    description, controllers = write_rover(tmp_path)
    text = description.read_text().replace(
        '<gazebo reference="left_wheel"><mu1>1.0</mu1><mu2>1.0</mu2></gazebo>',
        '<gazebo reference="left_wheel"><mu1>0.8</mu1><mu2>0.9</mu2><kp>1e6</kp>'
        '<kd>50</kd></gazebo>')
    description.write_text(text)
    with make_simulation(str(description), str(controllers), TIME_STEP,
                         fixed_base=None) as simulation:
        physics = simulation.physics
        info = pybullet.getDynamicsInfo(physics.body_id, physics.link_index('left_wheel'),
                                        physicsClientId=physics.client_id)
        assert info[FRICTION] == pytest.approx(0.8)  # the smaller of mu1 and mu2
        assert (info[STIFFNESS], info[DAMPING]) == pytest.approx((1e6, 50.0))


def test_the_robot_entity_of_a_free_base_reports_its_twist_and_can_be_moved(tmp_path):
    with rover(tmp_path) as simulation:
        entities = Entities(simulation.physics, 'rover')
        assert entities.has_ground
        drive(simulation, 0.2, 0.0, 1.0)
        state = entities.state('rover')
        assert state.linear[0] == pytest.approx(0.2, rel=0.02)
        assert state.pose.translation[0] == pytest.approx(
            simulation.physics.base_frame().translation[0])
        entities.reset_state()
        assert entities.state('rover').pose.translation == pytest.approx(
            (0.0, 0.0, REST_HEIGHT))


def test_a_drive_controller_left_inactive_leaves_the_base_welded(tmp_path):
    drive_params = drive_parameters()
    with rover(tmp_path, drive_params, active=['joint_state_broadcaster']) as simulation:
        assert simulation.physics.fixed_base


def test_waiting_for_spawners_a_robot_on_wheels_stands_free_and_an_arm_stays_welded(tmp_path):
    # A robot's own launch file: no controller declared, the spawners bring them later.
    log = Log()
    description, _ = write_rover(tmp_path)
    broadcaster = write_text(tmp_path, 'broadcaster.yaml', ros2_control_yaml({
        'joint_state_broadcaster': ('joint_state_broadcaster/JointStateBroadcaster', {})}))
    with make_simulation(str(description), str(broadcaster), TIME_STEP, fixed_base=None,
                         autostart_controllers=False, logger=log) as simulation:
        assert not simulation.physics.fixed_base
        assert simulation.physics.base_frame().translation == pytest.approx(
            (0.0, 0.0, REST_HEIGHT), abs=1e-9)
    assert any('stands on wheels (left_wheel_joint, right_wheel_joint)' in line
               for line in log.infos)
    arm = write_star_robot(tmp_path, [JointDef('joint1')])
    with make_simulation(str(arm), str(broadcaster), TIME_STEP, fixed_base=None,
                         autostart_controllers=False) as simulation:
        assert simulation.physics.fixed_base
