"""The browser view of an in-process sim_node (viewer:=true): served, idle, fed, controlled.

Several robots: a later one is drawn, and a deleted first robot leaves the view.

A "browser" here is a websocket client speaking viser's protocol version,
reading whatever the server sends; the real browser is in
``test/end_to_end/test_viewer_browser.py``.  The node runs on the test's
executor, so every wait spins it, bounded.
"""

import importlib.util
import threading
import urllib.request

import msgspec
import pytest
import sim_process
import viser
from node_harness import sim_node
from viser._messages import ViewerCameraMessage
from websockets.sync.client import connect

from pan_tilt_sim.ros.runner import EXIT_CONFIGURATION_ERROR
from pan_tilt_sim.ros.view_feed import FLOAT64

NS = '/ex_urdf_pan_tilt'
PAN = 'joint1_position_controller'
BUDGET_S = 30.0


class FakeBrowser:
    """A websocket client of the view that reads (and counts) everything sent to it.

    viser counts a client as connected once it reported its camera, as its
    web client does first thing.
    """

    def __init__(self, port: int) -> None:
        self._socket = connect(f'ws://127.0.0.1:{port}',
                               subprotocols=[f'viser-v{viser.__version__}'], max_size=None)
        camera = ViewerCameraMessage(wxyz=(1.0, 0.0, 0.0, 0.0), position=(2.0, 2.0, 2.0),
                                     fov=1.0, near=0.01, far=100.0, image_height=480,
                                     image_width=640, look_at=(0.0, 0.0, 0.0),
                                     up_direction=(0.0, 0.0, 1.0))
        self._socket.send(msgspec.msgpack.encode(camera.as_serializable_dict()))
        self.received = 0
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        try:
            for _message in self._socket:
                self.received += 1
        except Exception:  # closed
            return

    def close(self) -> None:
        self._socket.close()
        self._reader.join(5.0)


@pytest.fixture
def viewed():
    with sim_node(viewer=True, **{'viewer.port': 0}) as sim:
        yield sim


def in_a_thread(sim, action) -> None:
    """Run a control from another thread (as the browser's callbacks are) while spinning."""
    worker = threading.Thread(target=action)
    worker.start()
    assert sim.spin_until(lambda: not worker.is_alive(), BUDGET_S)


def test_the_page_is_served_on_the_port_the_url_names(viewed):
    viewer = viewed.node.viewer
    assert viewer.url == f'http://127.0.0.1:{viewer.settings.port}/'
    assert viewer.settings.port != 0
    with urllib.request.urlopen(viewer.url, timeout=BUDGET_S) as response:
        assert b'<html' in response.read().lower()


def test_nothing_is_computed_for_the_view_while_nobody_is_connected(viewed):
    viewer = viewed.node.viewer
    assert viewed.spin_until(viewer.idle.is_set, BUDGET_S)
    viewed.run_for(1.0)
    assert viewer.frames == 0
    assert viewer.access.calls == 0  # not one snapshot taken


def test_a_connected_browser_is_fed_and_after_it_leaves_nothing_more_is_computed(viewed):
    viewer = viewed.node.viewer
    browser = FakeBrowser(viewer.settings.port)
    try:
        assert viewed.spin_until(lambda: viewer.frames >= 3, BUDGET_S)
        assert browser.received > 0
    finally:
        browser.close()
    assert viewed.spin_until(lambda: viewer.clients == 0 and viewer.idle.is_set(), BUDGET_S)
    frames, calls = viewer.frames, viewer.access.calls
    viewed.run_for(1.0)
    assert (viewer.frames, viewer.access.calls) == (frames, calls)


def test_the_camera_is_subscribed_only_while_a_browser_shows_it(viewed):
    viewer = viewed.node.viewer
    image = f'{NS}/camera/image_raw'
    assert [entry.topic for entry in viewer.taps.topics] == [image]
    assert viewed.node.count_subscribers(image) == 0
    browser = FakeBrowser(viewer.settings.port)
    try:
        assert viewed.spin_until(lambda: viewer.taps.watching and image in viewer.taps.latest,
                                 BUDGET_S)
    finally:
        browser.close()
    assert viewed.spin_until(lambda: not viewer.taps.watching, BUDGET_S)
    assert viewed.spin_until(lambda: viewed.node.count_subscribers(image) == 0, BUDGET_S)


def test_a_slider_publishes_on_the_controllers_command_topic_as_a_user_would(viewed):
    viewer = viewed.node.viewer
    browser = FakeBrowser(viewer.settings.port)
    try:
        assert viewed.spin_until(lambda: len(viewer.sliders) == 2, BUDGET_S)
        pan = next(spec for spec in viewer.sliders if spec.joint == 'pan_joint')
        assert (pan.channel.topic, pan.channel.message) == (
            f'{NS}/{PAN}/command', FLOAT64)
        counts = viewed.node.commands_received
        before = counts[PAN]
        taken = viewed.simulation.controller(PAN)
        # The node's own subscription takes it, once DDS has matched the new publisher.
        assert viewed.spin_until(lambda: (viewer.command(pan, 0.5), counts[PAN] > before)[1],
                                 BUDGET_S)
        assert viewed.spin_until(lambda: taken.setpoints()['pan_joint'] > 0.0, BUDGET_S)
        viewed.run_for(10.0)  # 0.5 rad at the pan's 0.1 rad/s
        # Within what the joint's friction leaves against the PID (as test_sim_node).
        assert viewed.position('pan_joint') == pytest.approx(0.5, abs=0.015)
    finally:
        browser.close()


def test_pause_reset_and_the_real_time_factor_work_through_the_node(viewed):
    viewer = viewed.node.viewer
    viewed.run_for(0.5)
    in_a_thread(viewed, lambda: viewer.pause(True))
    assert viewed.node.paused
    before = viewed.simulation.time
    in_a_thread(viewed, viewer.reset)  # paused: no step runs after it before the check
    assert viewed.simulation.time < before
    in_a_thread(viewed, lambda: viewer.pause(False))
    assert not viewed.node.paused
    in_a_thread(viewed, lambda: viewer.set_real_time_factor(2.0))
    assert viewed.node.real_time_factor == 2.0
    assert viewed.node.get_parameter('real_time_factor').value == 2.0


def test_a_port_in_use_ends_start_up_with_one_line_before_the_simulation_starts():
    import socket

    with socket.socket() as taken:
        taken.bind(('127.0.0.1', 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = sim_process.run('-p', 'viewer:=true', '-p', f'viewer.port:={port}')
    assert result.returncode == EXIT_CONFIGURATION_ERROR, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert f"parameter 'viewer.port': port {port} on 127.0.0.1 is in use" in lines[0]
    assert 'simulating' not in result.stdout + result.stderr


@pytest.mark.skipif(importlib.util.find_spec('simulation_interfaces') is None,
                    reason='simulation_interfaces is not installed')
def test_a_later_robot_is_drawn_and_a_deleted_first_robot_leaves_the_view():
    from stand_in_fixtures import srv, two_rovers, world_only

    with world_only(viewer=True, **{'viewer.port': 0}) as (harness, node):
        two_rovers(harness)
        viewer = node.viewer
        browser = FakeBrowser(viewer.settings.port)
        try:
            assert harness.spin_until(
                lambda: {'/robot', '/objects/robot2'} <= set(viewer.drawn), BUDGET_S)
            response = harness.call(srv().DeleteEntity, '/sim_node/delete_entity',
                                    srv().DeleteEntity.Request(entity='robot1'))
            assert response.result.result == 1, response.result.error_message
            assert harness.spin_until(lambda: '/robot' not in viewer.drawn, BUDGET_S)
            frames = viewer.frames  # and the view goes on, robot2 in it
            assert harness.spin_until(lambda: viewer.frames > frames + 2, BUDGET_S)
            assert '/objects/robot2' in viewer.drawn
        finally:
            browser.close()
