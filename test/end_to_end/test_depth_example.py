"""End to end: examples/depth_snapshot.py against sim_node running the pan/tilt with sensors.

The sensor example of docs/sensors.md, as a user runs it: sim_node with
``urdf/pan_tilt_sensors.xacro`` in one process, the rclpy client in another;
the client turns the pan to face a target, saves the depth image as a PNG
and describes the point cloud.
"""

import subprocess
import sys

import pytest
import sim_process

from pan_tilt_sim.share import package_share

STARTUP_BUDGET_S = 60.0
SHUTDOWN_BUDGET_S = 5.0
PNG_MAGIC = b'\x89PNG\r\n\x1a\n'


@pytest.fixture
def sensor_sim():
    description = package_share() / 'urdf' / 'pan_tilt_sensors.xacro'
    process = sim_process.start('-p', f'robot_description_file:={description}',
                                '-p', 'real_time_factor:=0', start_new_session=True)
    yield process
    sim_process.stop(process, SHUTDOWN_BUDGET_S)


def test_the_depth_example_saves_a_png_and_sees_the_yellow_target_2_m_ahead(
        sensor_sim, repo_root, tmp_path):
    png = tmp_path / 'depth.png'
    result = subprocess.run(
        [sys.executable, str(repo_root / 'examples' / 'depth_snapshot.py'), '--pan', '1.5708',
         '--png', str(png), '--timeout', str(STARTUP_BUDGET_S)],
        capture_output=True, text=True, env=sim_process.environment(),
        timeout=STARTUP_BUDGET_S + 30, check=False)
    assert result.returncode == 0, result.stdout + result.stderr
    assert png.read_bytes().startswith(PNG_MAGIC)
    # The yellow cube's near face is 2.2 m from the pan axis, the camera 0.2 m out on it.
    assert 'depth image 320x240: centre 2.000 m' in result.stdout
    assert 'frame camera_optical_frame' in result.stdout
    centre = next(line for line in result.stdout.splitlines() if 'centre point' in line)
    red, green, blue = (int(value) for value in
                        centre.split('colour rgb (')[1].rstrip(')').split(','))
    assert red > 100 and green > 100 and blue < 60, centre  # yellow
