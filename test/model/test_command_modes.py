"""command_modes: which command interfaces a <ros2_control> block's hardware lets start.

Each block is read from a small URDF written here: two joints whose
``<ros2_control>`` entries give position, velocity, acceleration and effort,
under the hardware plugin each test names.
"""

import pathlib

import pytest

from pan_tilt_sim.model.command_modes import (
    MOCK_PLUGIN,
    MULTI_INTERFACE_DEMO_PLUGIN,
    mode_switch_refusal,
    system_claims,
)
from pan_tilt_sim.model.urdf import parse_urdf

GAZEBO_PLUGIN = 'gz_ros2_control/GazeboSimSystem'
INTERFACES = ('position', 'velocity', 'acceleration', 'effort')


def two_joint_system(plugin, params=''):
    """Return the <ros2_control> block of a two-joint robot whose hardware is ``plugin``."""
    joints = ''.join(
        f'<joint name="{name}">'
        + ''.join(f'<command_interface name="{interface}"/>' for interface in INTERFACES)
        + '<state_interface name="position"/></joint>' for name in ('joint1', 'joint2'))
    urdf = f"""<robot name="rr"><link name="base"/><link name="a"/><link name="b"/>
      <joint name="joint1" type="revolute"><parent link="base"/><child link="a"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="joint2" type="revolute"><parent link="a"/><child link="b"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <ros2_control name="RR" type="system">
        <hardware><plugin>{plugin}</plugin>{params}</hardware>{joints}
      </ros2_control></robot>"""
    (system,) = parse_urdf(urdf, pathlib.Path('rr.urdf')).ros2_control
    return system


def on_both(interface):
    return [('joint1', interface), ('joint2', interface)]


DYNAMICS = '<param name="calculate_dynamics">True</param>'


def test_the_block_claims_every_interface_it_gives_its_joints():
    claims = system_claims(two_joint_system(GAZEBO_PLUGIN))
    assert claims == {(joint, interface) for joint in ('joint1', 'joint2')
                      for interface in INTERFACES}


@pytest.mark.parametrize(('plugin', 'params'), [
    (GAZEBO_PLUGIN, ''),
    ('gazebo_ros2_control/GazeboSystem', ''),
    ('acme_driver/RobotHardware', ''),
    (MOCK_PLUGIN, ''),
    (MOCK_PLUGIN, '<param name="calculate_dynamics">false</param>'),
])
def test_gazebo_mock_without_dynamics_and_other_hardware_take_two_interfaces_on_a_joint(
        plugin, params):
    start = [('joint1', 'position'), ('joint1', 'velocity'), ('joint2', 'effort')]
    assert mode_switch_refusal(two_joint_system(plugin, params), start, [], set()) is None


def test_mock_hardware_with_dynamics_refuses_two_starting_interfaces_on_one_joint():
    system = two_joint_system(MOCK_PLUGIN, DYNAMICS)
    refusal = mode_switch_refusal(
        system, [('joint1', 'velocity'), ('joint2', 'position'), ('joint2', 'velocity')], [],
        set())
    assert refusal == (
        f"component 'RR' ({MOCK_PLUGIN}) did not accept command interfaces combination "
        '(start: joint1/velocity, joint2/position, joint2/velocity; stop: none): Got multiple '
        "(2) starting interfaces for joint 'joint2' - this is not supported!")


def test_mock_hardware_with_dynamics_needs_a_position_velocity_or_acceleration_mode():
    system = two_joint_system(MOCK_PLUGIN, DYNAMICS)
    refusal = mode_switch_refusal(system, [('joint2', 'effort')], [], set())
    assert refusal.endswith("Joint 'joint2' has to have 'position', 'velocity', or "
                            "'acceleration' interface!")


def test_mock_hardware_with_dynamics_takes_one_mode_per_joint_and_any_stop():
    system = two_joint_system(MOCK_PLUGIN, DYNAMICS)
    start = [('joint1', 'acceleration'), ('joint2', 'velocity')]
    assert mode_switch_refusal(system, start, on_both('position'), set(on_both('position'))) \
        is None
    assert mode_switch_refusal(system, [], on_both('velocity'), set(on_both('velocity'))) is None


# --- ros2_control_demos example 3's hardware ------------------------------------------------

@pytest.fixture
def demo():
    return two_joint_system(MULTI_INTERFACE_DEMO_PLUGIN)


def test_the_demo_hardware_takes_one_mode_on_all_its_joints_at_once(demo):
    for interface in ('position', 'velocity', 'acceleration'):
        assert mode_switch_refusal(demo, on_both(interface), [], set()) is None
    # Handing over from one mode to another in one switch.
    assert mode_switch_refusal(demo, on_both('position'), on_both('velocity'),
                               set(on_both('velocity'))) is None


def test_the_demo_hardware_refuses_a_mode_on_one_joint_only(demo):
    refusal = mode_switch_refusal(demo, [('joint1', 'position')], [], set())
    assert refusal == (
        f"component 'RR' ({MULTI_INTERFACE_DEMO_PLUGIN}) did not accept command interfaces "
        'combination (start: joint1/position; stop: none): all joints (joint1, joint2) must be '
        'given new command mode at the same time')


def test_the_demo_hardware_refuses_different_modes_on_its_joints(demo):
    refusal = mode_switch_refusal(demo, [('joint1', 'position'), ('joint2', 'velocity')], [],
                                  set())
    assert refusal.endswith(': all joints must have the same command mode (joint1/position, '
                            'joint2/velocity)')


def test_the_demo_hardware_refuses_two_modes_on_one_joint(demo):
    start = [*on_both('position'), ('joint1', 'velocity')]
    assert 'must be given new command mode at the same time' in mode_switch_refusal(
        demo, start, [], set())


def test_the_demo_hardware_refuses_stopping_without_a_new_mode(demo):
    refusal = mode_switch_refusal(demo, [], on_both('velocity'), set(on_both('velocity')))
    assert '(start: none; stop: joint1/velocity, joint2/velocity): all joints' in refusal


def test_the_demo_hardware_refuses_a_joint_still_in_use(demo):
    refusal = mode_switch_refusal(demo, on_both('position'), [('joint1', 'velocity')],
                                  set(on_both('velocity')))
    assert refusal.endswith(": joint 'joint2' is still in use by an active controller")


def test_a_switch_that_touches_none_of_its_interfaces_is_not_asked(demo):
    assert mode_switch_refusal(demo, [], [], set(on_both('velocity'))) is None
