"""Physical variations: the model and PyBullet's URDF copy change together, by the right amounts."""

import math
import xml.etree.ElementTree as ElementTree

import pytest

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.robot import Inertial
from pan_tilt_sim.model.transforms import Transform, quaternion_from_rpy
from pan_tilt_sim.model.variation import (
    PAYLOAD_RADIUS_M,
    Payload,
    PhysicalVariation,
    combined_inertial,
    vary_description,
)

SPHERE = 0.4 * PAYLOAD_RADIUS_M ** 2  # a 1 kg payload's own inertia about its centre


@pytest.fixture(scope='module')
def pan_tilt(request):
    root = request.config.rootpath
    return load_description(root / 'urdf' / 'pan_tilt.xacro')


def urdf_inertial(description, link):
    """Return (mass, {ixx..izz}, origin xyz) of ``link`` in PyBullet's URDF copy."""
    element = ElementTree.fromstring(description.physics_urdf).find(
        f"link[@name='{link}']/inertial")
    tensor = element.find('inertia').attrib
    origin = element.find('origin')
    xyz = tuple(float(v) for v in origin.get('xyz').split()) if origin is not None else None
    return float(element.find('mass').get('value')), {k: float(v) for k, v in tensor.items()}, xyz


def urdf_dynamics(description, joint):
    element = ElementTree.fromstring(description.physics_urdf).find(
        f"joint[@name='{joint}']/dynamics")
    return float(element.get('damping')), float(element.get('friction'))


def test_nothing_varied_is_the_same_description(pan_tilt):
    assert vary_description(pan_tilt, PhysicalVariation()) is pan_tilt
    assert vary_description(pan_tilt, PhysicalVariation(payload=Payload('pan_link', 0.0))) \
        is pan_tilt


def test_mass_scales_every_mass_and_inertia_in_the_model_and_the_urdf(pan_tilt):
    varied = vary_description(pan_tilt, PhysicalVariation(mass_scale=1.5))
    for link in varied.model.links:
        assert link.inertial.mass == pytest.approx(1.5)  # the pan/tilt's links are 1 kg, 1 kg m^2
        assert link.inertial.izz == pytest.approx(1.5)
        mass, tensor, _ = urdf_inertial(varied, link.name)
        assert mass == pytest.approx(1.5)
        assert tensor['ixx'] == tensor['iyy'] == tensor['izz'] == pytest.approx(1.5)


def test_inertia_scales_the_tensor_alone(pan_tilt):
    varied = vary_description(pan_tilt, PhysicalVariation(inertia_scale=0.5))
    mass, tensor, _ = urdf_inertial(varied, 'pan_link')
    assert mass == pytest.approx(1.0)
    assert tensor['izz'] == pytest.approx(0.5)
    assert varied.model.link('pan_link').inertial.izz == pytest.approx(0.5)


def test_friction_and_damping_scale_every_joint(pan_tilt):
    varied = vary_description(pan_tilt, PhysicalVariation(friction_scale=3.0,
                                                          damping_scale=0.2))
    for name in ('pan_joint', 'tilt_joint'):
        joint = varied.model.joint(name)
        assert (joint.damping, joint.friction) == pytest.approx((10.0, 3.0))
        assert urdf_dynamics(varied, name) == pytest.approx((10.0, 3.0))
    assert [j.name for j in varied.actuated_joints] == ['pan_joint', 'tilt_joint']


def test_the_description_as_written_and_the_original_stay_untouched(pan_tilt):
    before = pan_tilt.physics_urdf
    varied = vary_description(pan_tilt, PhysicalVariation(mass_scale=2.0, friction_scale=0.0))
    assert varied.urdf_xml == pan_tilt.urdf_xml
    assert pan_tilt.physics_urdf == before
    assert pan_tilt.model.joint('pan_joint').friction == 1.0


def test_a_payload_moves_the_centre_of_mass_and_adds_inertia_by_parallel_axes(pan_tilt):
    # 1 kg link (I = 1) at the origin + 1 kg at x = 0.2: centre at 0.1, each 0.1 away.
    varied = vary_description(pan_tilt, PhysicalVariation(
        payload=Payload('tilt_link', 1.0, (0.2, 0.0, 0.0))))
    inertial = varied.model.link('tilt_link').inertial
    assert inertial.mass == pytest.approx(2.0)
    assert inertial.origin.translation == pytest.approx((0.1, 0.0, 0.0))
    assert inertial.ixx == pytest.approx(1.0 + SPHERE)
    assert inertial.iyy == pytest.approx(1.0 + 2 * 0.01 + SPHERE)
    assert inertial.izz == pytest.approx(1.0 + 2 * 0.01 + SPHERE)
    mass, tensor, xyz = urdf_inertial(varied, 'tilt_link')
    assert mass == pytest.approx(2.0) and xyz == pytest.approx((0.1, 0.0, 0.0))
    assert tensor['iyy'] == pytest.approx(inertial.iyy)
    assert varied.model.link('pan_link').inertial.mass == pytest.approx(1.0)


def test_a_rotated_inertial_is_combined_in_the_link_frame():
    # diag(1, 2, 3) in a frame turned 90 degrees about z is diag(2, 1, 3) in the link frame.
    turned = Inertial(mass=1.0, origin=Transform(rotation=quaternion_from_rpy(0, 0, math.pi / 2)),
                      ixx=1.0, iyy=2.0, izz=3.0)
    combined = combined_inertial(turned, 1.0, (0.0, 0.0, 0.0))
    assert (combined.ixx, combined.iyy, combined.izz) == pytest.approx(
        (2.0 + SPHERE, 1.0 + SPHERE, 3.0 + SPHERE))
    assert (combined.ixy, combined.ixz, combined.iyz) == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)


def test_a_payload_on_a_link_without_inertial_becomes_its_inertial():
    combined = combined_inertial(None, 2.0, (0.0, 0.0, 0.5))
    assert combined.mass == 2.0
    assert combined.origin.translation == (0.0, 0.0, 0.5)
    assert combined.ixx == pytest.approx(2 * SPHERE)


def test_an_unknown_payload_link_is_refused(pan_tilt):
    with pytest.raises(DescriptionError, match="payload link 'gripper' is not a link"):
        vary_description(pan_tilt, PhysicalVariation(payload=Payload('gripper', 1.0)))


@pytest.mark.parametrize('fields', [{'mass_scale': 0.0}, {'friction_scale': -1.0},
                                    {'damping_scale': math.nan},
                                    {'payload': Payload('pan_link', -1.0)}])
def test_impossible_variations_are_refused(fields):
    with pytest.raises(DescriptionError):
        PhysicalVariation(**fields)


@pytest.mark.parametrize(('variation', 'expected'), [
    (PhysicalVariation(mass_scale=1e9), "link 'base_link': mass"),
    (PhysicalVariation(inertia_scale=1e12), "link 'base_link': inertia ixx"),
    (PhysicalVariation(payload=Payload('tilt_link', 2e6)), "link 'tilt_link': mass"),
])
def test_a_variation_beyond_what_the_parser_accepts_is_refused(pan_tilt, variation, expected):
    # PyBullet gets the varied copy: it must stay within the parser's bounds.
    with pytest.raises(DescriptionError) as refused:
        vary_description(pan_tilt, variation)
    assert expected in str(refused.value)
    assert 'beyond' in str(refused.value)
