"""Joint kinds in the engine (PyBullet, no ROS): revolute, continuous, prismatic, fixed, mimic."""

import math

import pytest
from robot_fixtures import LINK_MASS, JointDef, star_robot_urdf, write_text

from pan_tilt_sim.controllers.broadcasters.joint_state_broadcaster import JointStateBroadcaster
from pan_tilt_sim.errors import ControllerConfigError, DescriptionError
from pan_tilt_sim.sim.engine import make_simulation

DT = 0.001


def simulation(tmp_path, joints, controllers, urdf=None):
    """A star robot of ``joints`` with ROS 1-style ``controllers`` ({name: params})."""
    robot = tmp_path / 'robot.urdf'
    robot.write_text(urdf or star_robot_urdf(joints), encoding='utf-8')
    lines = ['joint_state_controller:', '  type: joint_state_controller/JointStateController',
             '  publish_rate: 100']
    for name, params in controllers.items():
        lines.append(f'{name}:')
        lines.extend(f'  {key}: {value}' for key, value in params.items())
    config = write_text(tmp_path, 'controllers.yaml', '\n'.join(lines) + '\n')
    return make_simulation(str(robot), str(config), DT)


def position_controller(joint, pid='{p: 100.0, i: 0.0, d: 10.0}'):
    return {'type': 'position_controllers/JointPositionController', 'joint': joint, 'pid': pid}


def effort_controller(joint):
    return {'type': 'effort_controllers/JointEffortController', 'joint': joint}


def run_seconds(sim, seconds):
    sim.advance(round(seconds / DT))


# --- revolute ------------------------------------------------------------------------------

def test_revolute_command_beyond_the_limit_stops_at_the_limit(tmp_path):
    joints = [JointDef('hinge', 'revolute', -0.5, 0.5, velocity=2.0)]
    with simulation(tmp_path, joints, {'pos': position_controller('hinge')}) as sim:
        sim.controller('pos').set_command(2.0)
        run_seconds(sim, 2.0)
        assert sim.joint_positions()['hinge'] == pytest.approx(0.5, abs=0.005)


# --- continuous ----------------------------------------------------------------------------

@pytest.mark.parametrize('target', [7.0, -10.0])
def test_continuous_joint_goes_past_a_full_turn_unclamped_and_unwrapped(tmp_path, target):
    joints = [JointDef('spin', 'continuous', None, None, velocity=10.0)]
    with simulation(tmp_path, joints, {'pos': position_controller('spin')}) as sim:
        sim.controller('pos').set_command(target)
        run_seconds(sim, 3.0)
        assert sim.joint_positions()['spin'] == pytest.approx(target, abs=0.005)


def test_continuous_joint_keeps_turning_under_constant_effort(tmp_path):
    joints = [JointDef('spin', 'continuous', None, None, damping=0.5)]
    with simulation(tmp_path, joints, {'eff': effort_controller('spin')}) as sim:
        sim.controller('eff').set_command(1.0)
        run_seconds(sim, 8.0)
        # Steady speed effort / damping = 2 rad/s, for well over a turn: no limit stops it.
        assert sim.joint_velocities()['spin'] == pytest.approx(2.0, rel=0.01)
        assert sim.joint_positions()['spin'] > 2 * math.pi


# --- prismatic -----------------------------------------------------------------------------

def test_prismatic_joint_is_commanded_in_metres_and_clamped_to_its_limits(tmp_path):
    joints = [JointDef('slide', 'prismatic', -0.1, 0.25, velocity=0.5)]
    with simulation(tmp_path, joints, {'pos': position_controller(
            'slide', '{p: 1000.0, i: 0.0, d: 100.0}')}) as sim:
        sim.controller('pos').set_command(0.2)
        run_seconds(sim, 1.5)
        assert sim.joint_positions()['slide'] == pytest.approx(0.2, abs=0.002)
        sim.controller('pos').set_command(-0.4)
        run_seconds(sim, 2.0)
        assert sim.joint_positions()['slide'] == pytest.approx(-0.1, abs=0.002)


def test_prismatic_effort_is_a_force_in_newtons(tmp_path):
    joints = [JointDef('slide', 'prismatic', -5.0, 5.0, damping=2.0)]
    with simulation(tmp_path, joints, {'eff': effort_controller('slide')}) as sim:
        sim.controller('eff').set_command(1.0)
        run_seconds(sim, 0.5)
        # m v' = F - b v: v(t) = (F / b) (1 - exp(-b t / m)), with m the link's mass in kg.
        expected = 1.0 / 2.0 * (1.0 - math.exp(-2.0 * 0.5 / LINK_MASS))
        assert sim.joint_velocities()['slide'] == pytest.approx(expected, rel=0.02)


# --- axes ----------------------------------------------------------------------------------

@pytest.mark.parametrize(('kind', 'unit', 'longer'), [
    ('revolute', '0 0 1', '0 0 3'), ('prismatic', '1 0 0', '0.25 0 0')])
def test_an_axis_is_a_direction_its_length_changes_nothing(tmp_path, kind, unit, longer):
    # URDF's axis is a unit vector; PyBullet, given a longer one, would move the joint with
    # other dynamics (revolute) or report its position in other units (prismatic).
    def motion(axis):
        folder = tmp_path / axis.replace(' ', '_')
        folder.mkdir()
        urdf = star_robot_urdf([JointDef('j', kind, -5.0, 5.0, damping=2.0)]).replace(
            f'<axis xyz="{unit}"/>', f'<axis xyz="{axis}"/>')
        with simulation(folder, [], {'eff': effort_controller('j')}, urdf=urdf) as sim:
            sim.controller('eff').set_command(1.0)
            run_seconds(sim, 0.5)
            return sim.joint_positions()['j'], sim.joint_velocities()['j']

    position, velocity = motion(unit)
    assert abs(position) > 0.01
    assert motion(longer) == pytest.approx((position, velocity), rel=1e-9)


# --- fixed ---------------------------------------------------------------------------------

def test_fixed_joints_are_skipped(tmp_path):
    urdf = star_robot_urdf([JointDef('hinge'), JointDef('weld')]).replace(
        'name="weld" type="revolute"', 'name="weld" type="fixed"')
    with simulation(tmp_path, [], {}, urdf=urdf) as sim:
        broadcaster = next(c for c in sim.controllers if isinstance(c, JointStateBroadcaster))
        assert list(sim.joint_positions()) == ['hinge']
        assert broadcaster.names == ['hinge']


def test_a_fixed_joint_cannot_be_commanded(tmp_path):
    urdf = star_robot_urdf([JointDef('hinge'), JointDef('weld')]).replace(
        'name="weld" type="revolute"', 'name="weld" type="fixed"')
    with pytest.raises(ControllerConfigError, match="joint 'weld' is a fixed joint"):
        simulation(tmp_path, [], {'pos': position_controller('weld')}, urdf=urdf)


# --- mimic ---------------------------------------------------------------------------------

MIMIC_JOINTS = [
    JointDef('leader', 'revolute', -1.0, 1.0, velocity=1.0),
    JointDef('follower', 'revolute', -3.0, 3.0, mimic=('leader', -2.0, 0.3)),
    JointDef('slide', 'prismatic', -0.2, 0.2, velocity=0.2),
    JointDef('slide_twin', 'prismatic', -0.2, 0.3, mimic=('slide', 1.0, 0.05)),
]


def mimic_errors(positions):
    return (positions['follower'] - (-2.0 * positions['leader'] + 0.3),
            positions['slide_twin'] - (positions['slide'] + 0.05))


def test_mimic_joints_start_where_their_leaders_put_them(tmp_path):
    with simulation(tmp_path, MIMIC_JOINTS, {}) as sim:
        positions = sim.joint_positions()
        assert (positions['follower'], positions['slide_twin']) == pytest.approx((0.3, 0.05))
        run_seconds(sim, 0.5)
        assert mimic_errors(sim.joint_positions()) == pytest.approx((0.0, 0.0), abs=1e-6)


def test_mimic_joints_follow_their_leaders_throughout_a_motion(tmp_path):
    controllers = {'lead': position_controller('leader'),
                   'slider': position_controller('slide', '{p: 1000.0, i: 0.0, d: 100.0}')}
    with simulation(tmp_path, MIMIC_JOINTS, controllers) as sim:
        sim.controller('lead').set_command(0.8)
        sim.controller('slider').set_command(-0.15)
        worst = 0.0
        for _ in range(150):
            sim.advance(10)
            worst = max(worst, *map(abs, mimic_errors(sim.joint_positions())))
        positions = sim.joint_positions()
    assert positions['leader'] == pytest.approx(0.8, abs=0.01)
    assert positions['follower'] == pytest.approx(-1.3, abs=0.02)
    assert positions['slide_twin'] == pytest.approx(-0.1, abs=0.002)
    assert worst < 1e-3


def test_mimic_follower_loads_its_leader_like_a_rigid_linkage(tmp_path):
    # Follower turning at -2x the leader: its damping b reflects as 2^2 * b on the leader.
    joints = [JointDef('leader', 'revolute', -10.0, 10.0, damping=0.5),
              JointDef('follower', 'revolute', -30.0, 30.0, damping=0.5,
                       mimic=('leader', -2.0, 0.0))]
    with simulation(tmp_path, joints, {'eff': effort_controller('leader')}) as sim:
        sim.controller('eff').set_command(1.0)
        run_seconds(sim, 3.0)
        velocities = sim.joint_velocities()
    assert velocities['leader'] == pytest.approx(1.0 / (0.5 + 4 * 0.5), rel=0.02)
    assert velocities['follower'] == pytest.approx(-2.0 * velocities['leader'], rel=1e-3)


def test_mimic_joints_are_back_on_their_leaders_after_reset(tmp_path):
    with simulation(tmp_path, MIMIC_JOINTS, {'lead': position_controller('leader')}) as sim:
        sim.controller('lead').set_command(0.5)
        run_seconds(sim, 1.0)
        sim.reset()
        positions = sim.joint_positions()
    assert (positions['leader'], positions['follower']) == pytest.approx((0.0, 0.3))


def test_mimic_joints_are_in_joint_states_but_cannot_be_commanded(tmp_path):
    with simulation(tmp_path, MIMIC_JOINTS, {}) as sim:
        broadcaster = next(c for c in sim.controllers if isinstance(c, JointStateBroadcaster))
        assert broadcaster.names == ['leader', 'follower', 'slide', 'slide_twin']
    with pytest.raises(ControllerConfigError,
                       match=r"pos\.joint: joint 'follower' mimics 'leader'"):
        simulation(tmp_path, MIMIC_JOINTS, {'pos': position_controller('follower')})


def test_mimic_of_a_fixed_joint_is_a_description_error(tmp_path):
    urdf = star_robot_urdf([JointDef('weld'), JointDef('follower', mimic=('weld', 1.0, 0.0))])
    urdf = urdf.replace('name="weld" type="revolute"', 'name="weld" type="fixed"')
    with pytest.raises(DescriptionError, match="'follower' mimics 'weld', which is not a movable"):
        simulation(tmp_path, [], {}, urdf=urdf)

