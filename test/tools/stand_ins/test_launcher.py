"""How every ROS-side stand-in runs: one node, its body's exit code, rclpy down afterwards."""

from __future__ import annotations

import pytest
import rclpy

from pan_tilt_sim.tools.stand_ins.launcher import exit_with, run_node


@pytest.fixture(autouse=True)
def _no_context_of_our_own():
    if rclpy.ok():
        pytest.skip('rclpy is already up in this process')
    yield
    assert not rclpy.ok(), 'run_node left rclpy up'


def test_the_body_runs_on_a_node_of_that_name_with_the_words_and_its_code_is_returned():
    seen = {}

    def body(node, words: list[str]) -> int:
        seen['name'], seen['words'] = node.get_name(), words
        return 7

    argv = ['create', '-name', 'rover', '--ros-args', '-p', 'x:=1.0']
    assert run_node(argv, 'ros_gz_sim', body) == 7
    assert seen == {'name': 'ros_gz_sim', 'words': ['-name', 'rover']}


def test_ctrl_c_in_the_body_exits_0_and_shuts_rclpy_down():
    def body(node, words: list[str]) -> int:
        raise KeyboardInterrupt

    assert run_node(['image_bridge', '/camera'], 'ros_gz_image', body) == 0


def test_an_error_in_the_body_still_shuts_rclpy_down():
    def body(node, words: list[str]) -> int:
        raise ValueError('broken stand-in')

    with pytest.raises(ValueError, match='broken stand-in'):
        run_node(['parameter_bridge', 'a@b@c'], 'ros_gz_bridge', body)


def test_the_process_exits_with_the_code_run_returns():
    with pytest.raises(SystemExit) as exited:
        exit_with(lambda argv: len(argv), ['spawn_entity.py', '-entity', 'rover'])
    assert exited.value.code == 3
