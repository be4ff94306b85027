"""The browser view in a real browser: sim_node with viewer:=true, rendered by headless Chromium.

The program serves the view on a free port (it logs the URL); Chromium opens
it and takes screenshots over the DevTools protocol (``test/end_to_end/browser.py``).
The page must show the pan/tilt: its blue pan link and its red tilt link on
the 3D canvas; after a pan command from the test process, the red link's
pixels must have moved.  Where Chromium cannot be had, the test skips saying
so (in CI, which installs it, that is a failure).
"""

import os
import pathlib
import re
import tempfile
import threading
import time

import browser
import numpy as np
import pytest
import sim_process
from node_harness import PROBE_QUEUE, NodeHarness
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

NS = '/ex_urdf_pan_tilt'
URL_LINE = re.compile(r'viewer: open (http://\S+) in a browser')
STARTUP_BUDGET_S = 60.0
RENDER_BUDGET_S = 90.0
SHUTDOWN_BUDGET_S = 10.0
PAN_TARGET = 1.5  # rad: the tilt link swings round by this much
CANVAS_WIDTH = 440  # px of the 800-wide page left of viser's control panel
MIN_LINK_PIXELS = 300  # a link that is drawn covers more than this
# The red tilt link, centred on the pan axis, turns from along x to along y: the pixels
# it covers after must overlap those before by less than this (intersection / union).
MAX_OVERLAP = 0.5


def link_pixels(pixels: np.ndarray) -> dict[str, np.ndarray]:
    """Masks of the pan/tilt's links on the 3D canvas: blue pan link, red tilt link (lit)."""
    canvas = pixels[:, :CANVAS_WIDTH].astype(int)
    r, g, b = canvas[..., 0], canvas[..., 1], canvas[..., 2]
    return {'blue': (b > r + 60) & (b > g + 60), 'red': (r > g + 60) & (r > b + 60)}


def robot_drawn(pixels: np.ndarray) -> bool:
    """Whether both moving links are on the canvas."""
    return all(mask.sum() > MIN_LINK_PIXELS for mask in link_pixels(pixels).values())


def overlap(a: np.ndarray, b: np.ndarray) -> float:
    """Intersection over union of two masks."""
    return float((a & b).sum() / max((a | b).sum(), 1))


@pytest.fixture
def chromium():
    found = browser.find_chromium()
    if found is None:
        if os.environ.get('CI'):
            pytest.fail(browser.NOT_INSTALLED)  # CI installs it: a skip would hide a break
        pytest.skip(browser.NOT_INSTALLED)
    return found


@pytest.fixture
def served():
    """sim_node with the view on a free port, at 10x real time; yields the view's URL."""
    process = sim_process.start('-p', 'viewer:=true', '-p', 'viewer.port:=0',
                                '-p', 'real_time_factor:=10')
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(process.stderr), daemon=True)
    reader.start()
    try:
        url = browser.wait_until(
            lambda: next((m.group(1) for line in list(lines) if (m := URL_LINE.search(line))),
                         None) or (process.poll() is not None and 'ended'),
            STARTUP_BUDGET_S, 'sim_node did not log the view URL')
        assert url != 'ended', ''.join(lines)
        yield url
    finally:
        process.send_signal(2)
        try:
            process.wait(SHUTDOWN_BUDGET_S)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()


def test_the_view_shows_the_robot_and_its_pixels_move_after_a_joint_command(chromium, served):
    harness = NodeHarness()
    page = browser.Browser(chromium)
    folder = pathlib.Path(tempfile.mkdtemp(prefix='pan_tilt_sim_view_'))
    try:
        page.open(served)
        before = page.screenshot_when(robot_drawn, RENDER_BUDGET_S,
                                      'the view never showed the pan/tilt')
        browser.save(before, folder / 'before.png')
        # Not blank: a lit scene of many shades, the robot among them.
        assert before.reshape(-1, 3).std(axis=0).mean() > 10.0
        assert len(np.unique(before.reshape(-1, 3), axis=0)) > 100

        states: list[JointState] = []
        harness.probe.create_subscription(JointState, f'{NS}/joint_states', states.append,
                                          PROBE_QUEUE)
        command = harness.probe.create_publisher(
            Float64, f'{NS}/joint1_position_controller/command', 10)
        assert harness.spin_until(lambda: command.get_subscription_count() > 0,
                                  STARTUP_BUDGET_S), 'sim_node does not subscribe the command'
        sent = [0.0]

        def reached() -> bool:
            # Sent again each second until it arrives: the same command, a repeat changes nothing.
            if time.monotonic() - sent[0] > 1.0:
                command.publish(Float64(data=PAN_TARGET))
                sent[0] = time.monotonic()
            return bool(states) and abs(states[-1].position[0] - PAN_TARGET) < 0.05
        assert harness.spin_until(reached, STARTUP_BUDGET_S), (
            f'the pan did not reach its command: {states[-1].position if states else None}')

        red_before = link_pixels(before)['red']
        after = page.screenshot_when(
            lambda pixels: robot_drawn(pixels) and overlap(
                link_pixels(pixels)['red'], red_before) < MAX_OVERLAP,
            RENDER_BUDGET_S, 'the red tilt link did not move on the screen')
        browser.save(after, folder / 'after.png')
    finally:
        page.close()
        harness.close()
