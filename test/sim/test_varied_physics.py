"""A varied description reaches PyBullet: masses, inertias, damping, and the motion they cause."""

import pytest

from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.variation import Payload, PhysicalVariation, vary_description
from pan_tilt_sim.sim.physics import Physics, pybullet


@pytest.fixture(scope='module')
def pan_tilt(request):
    return load_description(request.config.rootpath / 'urdf' / 'pan_tilt.xacro')


def dynamics(physics, link):
    """Return PyBullet's (mass, local inertia diagonal, local inertial position) of ``link``."""
    info = pybullet.getDynamicsInfo(physics.body_id, physics.link_index(link),
                                    physicsClientId=physics.client_id)
    return info[0], info[2], info[3]


def test_pybullet_loads_the_varied_masses_inertias_and_damping(pan_tilt):
    varied = vary_description(pan_tilt, PhysicalVariation(
        mass_scale=2.0, damping_scale=0.5, payload=Payload('tilt_link', 2.0, (0.2, 0.0, 0.0))))
    with Physics(varied, 0.001) as physics:
        mass, inertia, _ = dynamics(physics, 'pan_link')
        assert mass == pytest.approx(2.0) and inertia == pytest.approx((2.0, 2.0, 2.0))
        mass, inertia, centre = dynamics(physics, 'tilt_link')
        assert mass == pytest.approx(4.0)
        assert centre == pytest.approx((0.1, 0.0, 0.0))
        assert inertia[1] == pytest.approx(varied.model.link('tilt_link').inertial.iyy)
        damping = pybullet.getJointInfo(physics.body_id, physics.joint_index('pan_joint'),
                                        physicsClientId=physics.client_id)[6]
        assert damping == pytest.approx(25.0)


def trajectory(description, efforts, steps=3000):
    """Return the joint states after each of ``steps`` steps under constant ``efforts``."""
    with Physics(description, 0.001) as physics:
        return [tuple(state[:2] for state in physics.step(efforts)) for _ in range(steps)]


def rewritten_xacro(repo_root, tmp_path, replacements):
    """Write the pan/tilt xacro with text replaced (the variation written by hand)."""
    text = (repo_root / 'urdf' / 'pan_tilt.xacro').read_text()
    for old, new in replacements:
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / 'pan_tilt.xacro'
    path.write_text(text)
    return load_description(path)


def test_varied_damping_and_friction_move_the_robot_as_the_urdf_written_so(
        pan_tilt, repo_root, tmp_path):
    by_hand = rewritten_xacro(repo_root, tmp_path, [(
        '<dynamics damping="50" friction="1"/>', '<dynamics damping="10" friction="0.2"/>')])
    varied = vary_description(pan_tilt, PhysicalVariation(damping_scale=0.2,
                                                          friction_scale=0.2))
    assert trajectory(varied, [5.0, 2.0]) == trajectory(by_hand, [5.0, 2.0])
    assert trajectory(varied, [5.0, 2.0]) != trajectory(pan_tilt, [5.0, 2.0])


def test_varied_mass_and_inertia_move_the_robot_as_the_urdf_written_so(
        pan_tilt, repo_root, tmp_path):
    by_hand = rewritten_xacro(repo_root, tmp_path, [
        ('<mass value="${mass}"/>', '<mass value="${mass * 3}"/>'),
        ('ixx="1.0" ixy="0.0" ixz="0.0" iyy="1.0" iyz="0.0" izz="1.0"',
         'ixx="1.5" ixy="0.0" ixz="0.0" iyy="1.5" iyz="0.0" izz="1.5"')])
    varied = vary_description(pan_tilt, PhysicalVariation(mass_scale=3.0, inertia_scale=0.5))
    assert trajectory(varied, [50.0, 20.0]) == trajectory(by_hand, [50.0, 20.0])
    assert trajectory(varied, [50.0, 20.0]) != trajectory(pan_tilt, [50.0, 20.0])
