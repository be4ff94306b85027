"""The ros2_control_node stand-in: sim_node, named controller_manager by default."""

from pan_tilt_sim.tools.stand_ins.ros2_control_node import arguments


def test_it_is_named_controller_manager_as_ros2_control_node_is():
    assert arguments(['ros2_control_node', '--ros-args', '--params-file', 'c.yaml']) == [
        'ros2_control_node', '--ros-args', '--params-file', 'c.yaml',
        '--ros-args', '-r', '__node:=controller_manager']


def test_a_name_launch_gives_it_stays():
    given = ['ros2_control_node', '--ros-args', '-r', '__node:=my_manager']
    assert arguments(given) == given
