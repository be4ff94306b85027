"""Loading one-link URDFs with meshes into a PyBullet client, for mesh tests.

Every test uses its own DIRECT client (the ``client`` fixture in
conftest.py) and disconnects it.  PyBullet prints loader warnings on stdout
from C; :func:`assert_quiet` reads them with ``capfd``.
"""

import pathlib
import xml.etree.ElementTree as ET

import mesh_fixtures as mf
import numpy as np
import pybullet
import pytest

MM = 0.001


MILLI_SCALE = '0.001 0.001 0.001'


FLOAT32_TOLERANCE = 1e-6


BOX_123: mf.Size = (1.0, 2.0, 3.0)


INERTIAL = ('<inertial><mass value="1"/>'
            '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>')


PRIMITIVE_COLLISION = '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'


def mesh_xml(uri: str, scale: str | None = None) -> str:
    """Return a ``<geometry><mesh>`` snippet."""
    scale_attr = f' scale="{scale}"' if scale is not None else ''
    return f'<geometry><mesh filename="{uri}"{scale_attr}/></geometry>'


def one_link_robot(visual: str = '', collision: str = '') -> ET.Element:
    """Return a parsed one-link URDF whose link ``m`` holds the given snippets."""
    return ET.fromstring(f'<robot name="t"><link name="m">{visual}{collision}{INERTIAL}'
                         '</link></robot>')


def mesh_robot(uri: str, role: str, scale: str | None = None) -> ET.Element:
    """Return a one-link URDF with ``uri`` as its visual or collision mesh.

    A visual mesh gets a primitive collision box beside it.
    """
    snippet = f'<{role}>{mesh_xml(uri, scale)}</{role}>'
    if role == 'visual':
        return one_link_robot(visual=snippet, collision=PRIMITIVE_COLLISION)
    return one_link_robot(collision=snippet)


def load(client_id: int, robot: ET.Element, folder: pathlib.Path) -> int:
    """Write ``robot`` to a file in ``folder``, load it into PyBullet and return the body."""
    path = folder / f'{robot.get("name")}-loaded.urdf'
    path.write_bytes(ET.tostring(robot))
    return pybullet.loadURDF(str(path), physicsClientId=client_id)


def collision_extent(client_id: int, body: int, link: int = -1) -> np.ndarray:
    """Return the size of a link's collision mesh as PyBullet holds it (scale applied)."""
    _, vertices = pybullet.getMeshData(body, link, physicsClientId=client_id)
    points = np.array(vertices)
    return points.max(axis=0) - points.min(axis=0)


def assert_quiet(capfd: pytest.CaptureFixture[str]) -> None:
    """Fail if PyBullet printed a loader warning or error."""
    out, err = capfd.readouterr()
    assert 'b3Warning' not in out + err
    assert 'b3Error' not in out + err
