"""What PyBullet itself does that the sensors build on (pan_tilt_sim.sim.sensors).

A failure here means PyBullet changed: the joint force-torque sensor's frame,
reference point or sign, the depth buffer's encoding, or what a ray cast
from inside a shape reports.
"""

import math

import numpy
import pytest

from pan_tilt_sim.sim.bullet import pybullet, quiet_native_output

MASS = 2.0
GRAVITY = 9.81


@pytest.fixture
def client():
    with quiet_native_output():
        connected = pybullet.connect(pybullet.DIRECT)
    pybullet.setGravity(0, 0, -GRAVITY, physicsClientId=connected)
    yield connected
    pybullet.disconnect(physicsClientId=connected)


def hanging_weight(client, tmp_path, inertial_xyz: str, inertial_rpy: str = '0 0 0') -> int:
    path = tmp_path / 'hang.urdf'
    path.write_text(f"""<robot name="hang">
      <link name="base"><inertial><mass value="1"/>
        <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <link name="weight"><inertial><origin xyz="{inertial_xyz}" rpy="{inertial_rpy}"/>
        <mass value="{MASS}"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
      </inertial></link>
      <joint name="hold" type="fixed"><parent link="base"/><child link="weight"/>
        <origin xyz="0 0 1"/></joint>
    </robot>""")
    with quiet_native_output():
        body = pybullet.loadURDF(str(path), useFixedBase=True,
                                 flags=pybullet.URDF_USE_INERTIA_FROM_FILE,
                                 physicsClientId=client)
    pybullet.enableJointForceTorqueSensor(body, 0, True, physicsClientId=client)
    for _ in range(10):
        pybullet.stepSimulation(physicsClientId=client)
    return body


def reaction(client, body):
    return numpy.array(pybullet.getJointState(body, 0, physicsClientId=client)[2])


def test_the_reaction_is_what_the_parent_applies_on_the_child(client, tmp_path):
    body = hanging_weight(client, tmp_path, '0 0 -0.2')
    assert reaction(client, body) == pytest.approx((0, 0, MASS * GRAVITY, 0, 0, 0), abs=1e-6)


def test_the_reaction_moment_is_about_the_childs_centre_of_mass(client, tmp_path):
    # Offset sideways, the weight needs a moment about the joint, none about itself.
    body = hanging_weight(client, tmp_path, '0.3 0 0')
    assert reaction(client, body) == pytest.approx((0, 0, MASS * GRAVITY, 0, 0, 0), abs=1e-6)


def test_the_reaction_is_in_the_childs_inertial_axes(client, tmp_path):
    body = hanging_weight(client, tmp_path, '0 0 0', f'{math.pi / 2} 0 0')
    # The inertial frame is rolled 90 degrees: world up is its +y.
    assert reaction(client, body)[:3] == pytest.approx((0, MASS * GRAVITY, 0), abs=1e-3)


def test_the_depth_buffer_is_opengl_depth_of_a_perspective_projection(client):
    near, far, distance = 0.1, 10.0, 2.0
    shape = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.01, 5, 5],
                                          physicsClientId=client)
    visual = pybullet.createVisualShape(pybullet.GEOM_BOX, halfExtents=[0.01, 5, 5],
                                        physicsClientId=client)
    pybullet.createMultiBody(0, shape, visual, basePosition=[distance + 0.01, 0, 0],
                             physicsClientId=client)
    view = pybullet.computeViewMatrix([0, 0, 0], [1, 0, 0], [0, 0, 1], physicsClientId=client)
    projection = pybullet.computeProjectionMatrixFOV(45, 1.0, near, far, physicsClientId=client)
    _, _, _, depth, _ = pybullet.getCameraImage(8, 8, view, projection,
                                                renderer=pybullet.ER_TINY_RENDERER,
                                                physicsClientId=client)
    buffer = numpy.asarray(depth, dtype=float)
    ndc = 2 * buffer - 1
    z = 2 * far * near / (far + near - ndc * (far - near))
    assert z.ravel() == pytest.approx(numpy.full(64, distance), rel=1e-4)


def test_a_ray_starting_inside_a_shape_does_not_hit_it(client):
    shape = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.5, 0.5, 0.5],
                                          physicsClientId=client)
    pybullet.createMultiBody(0, shape, basePosition=[0, 0, 0], physicsClientId=client)
    inside, = pybullet.rayTestBatch([[0, 0, 0]], [[3, 0, 0]], physicsClientId=client)
    outside, = pybullet.rayTestBatch([[-3, 0, 0]], [[0, 0, 0]], physicsClientId=client)
    assert inside[0] == -1  # nothing hit: a lidar inside its own link's shape sees out
    assert outside[0] >= 0 and outside[2] == pytest.approx(2.5 / 3)
