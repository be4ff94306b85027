"""What PyBullet 3.2.7 does with meshes: the facts mesh localization is built on.

A failure here means PyBullet changed, not pan_tilt_sim.
"""

import mesh_fixtures as mf
import numpy as np
import pybullet
from mesh_loading import FLOAT32_TOLERANCE, MILLI_SCALE, MM, collision_extent, load, mesh_robot

from pan_tilt_sim.model.resources import localize_meshes


def test_pybullet_alone_silently_drops_an_ascii_stl(tmp_path, client, capfd):
    """Why ASCII STL is converted: PyBullet loads the link without a shape and only prints."""
    mf.write_ascii_stl(tmp_path / 'ascii.stl')
    body = load(client, mesh_robot(str(tmp_path / 'ascii.stl'), 'collision'), tmp_path)
    assert pybullet.getCollisionShapeData(body, -1, physicsClientId=client) == ()
    assert 'cannot extract mesh' in capfd.readouterr().out


def test_scale_shrinks_a_one_metre_box_to_one_millimetre(tmp_path, cache_dir, client):
    """PyBullet applies scale="0.001 0.001 0.001" itself: a 1 m box becomes 1 mm."""
    mf.write_binary_stl(tmp_path / 'box.stl')
    robot = mesh_robot('box.stl', 'collision', MILLI_SCALE)
    localize_meshes(robot, tmp_path, cache_dir)
    body = load(client, robot, tmp_path)
    lower, upper = pybullet.getAABB(body, -1, physicsClientId=client)
    aabb_size = np.subtract(upper, lower)
    collision_margin = 2 * 0.002  # Bullet pads convex hulls by 2 mm on each side.
    np.testing.assert_allclose(aabb_size, MM + collision_margin, rtol=FLOAT32_TOLERANCE)
    np.testing.assert_allclose(collision_extent(client, body), [MM] * 3, rtol=FLOAT32_TOLERANCE)


def test_pybullet_honours_anisotropic_scale(tmp_path, cache_dir, client):
    """PyBullet applies a per-axis scale as given."""
    mf.write_binary_stl(tmp_path / 'box.stl')
    robot = mesh_robot('box.stl', 'collision', '2 3 4')
    localize_meshes(robot, tmp_path, cache_dir)
    body = load(client, robot, tmp_path)
    np.testing.assert_allclose(collision_extent(client, body), [2, 3, 4], rtol=FLOAT32_TOLERANCE)
