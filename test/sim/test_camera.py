"""The camera on the tilt link: intrinsics, mounting, what it sees, and its topics."""

import math

import numpy
import pytest
from node_harness import sim_node
from sensor_msgs.msg import CameraInfo, Image
from std_srvs.srv import Empty

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.transforms import rotate
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim.camera import (
    CameraSettings,
    Renderer,
    camera_mount,
    intrinsics,
    nothing_drawn,
    vertical_fov_deg,
)
from pan_tilt_sim.sim.physics import Physics
from pan_tilt_sim.sim.world import GROUND_RGB, TARGET_SET, Target, build_world

HORIZONTAL_TILT = -math.pi / 2  # the pan/tilt example's tilt start: the camera looks horizontally
PAN_LIMIT = 3.14
# The centre patch of the image, in pixels either side of the centre.
CENTRE_HALF = 8
# A pixel "is" a colour when its chromaticity (rgb / sum) is this close to the colour's.
CHROMA_TOLERANCE = 0.08
DOMINANT = 0.9  # fraction of the centre patch a faced target must cover


@pytest.fixture(scope='module')
def pan_tilt_description():
    """Return the project's pan/tilt model."""
    return load_description(package_share() / DEFAULT_DESCRIPTION)


class Scene:
    """The pan/tilt example in its own simulation, its camera, the world around it."""

    def __init__(self, description, world: str = 'targets') -> None:
        self.physics = Physics(description, 0.001)
        build_world(world, self.physics.client_id)
        self.settings = CameraSettings()
        self.renderer = Renderer(self.physics, description.model, self.settings, world)

    def render(self, positions) -> bytes:
        """Put the joints at ``positions`` (pan, tilt) and render."""
        self.physics.reset_joints(positions)
        return self.renderer.render()

    def optical_axes(self):
        return self.renderer.optical_axes()

    def close(self) -> None:
        self.physics.close()


@pytest.fixture(scope='module')
def renderer(pan_tilt_description):
    """Return the default camera in the default (targets) world."""
    scene = Scene(pan_tilt_description)
    yield scene
    scene.close()


def as_array(pixels: bytes, settings: CameraSettings) -> numpy.ndarray:
    """Return an rgb8 image as a height x width x 3 array."""
    return numpy.frombuffer(pixels, numpy.uint8).reshape(settings.height, settings.width, 3)


def colour_mask(image: numpy.ndarray, rgba) -> numpy.ndarray:
    """Return where ``image`` has the hue of ``rgba`` (whatever the shading)."""
    wanted = numpy.array(rgba[:3]) / sum(rgba[:3])
    total = image.astype(float).sum(axis=2, keepdims=True)
    chroma = image / numpy.maximum(total, 1.0)
    return numpy.abs(chroma - wanted).max(axis=2) < CHROMA_TOLERANCE


def centre(image: numpy.ndarray) -> numpy.ndarray:
    """Return the centre patch of ``image``."""
    rows, columns = image.shape[:2]
    return image[rows // 2 - CENTRE_HALF:rows // 2 + CENTRE_HALF,
                 columns // 2 - CENTRE_HALF:columns // 2 + CENTRE_HALF]


def pan_facing(target: Target) -> float:
    """Return the pan angle at which the pan/tilt example's camera looks at ``target``."""
    pan = math.remainder(math.radians(target.azimuth_deg) - math.pi, 2 * math.pi)
    return max(-PAN_LIMIT, min(PAN_LIMIT, pan))


# --- intrinsics -----------------------------------------------------------------

def test_camera_info_intrinsics_follow_the_horizontal_fov_and_the_size():
    camera = intrinsics(CameraSettings(width=320, height=240, fov_deg=60.0))
    focal = 160.0 / math.tan(math.radians(30.0))
    assert camera.fx == pytest.approx(focal) and camera.fy == pytest.approx(focal)
    assert (camera.cx, camera.cy) == (159.5, 119.5)
    assert camera.k == pytest.approx((focal, 0, 159.5, 0, focal, 119.5, 0, 0, 1))
    assert camera.p == pytest.approx((focal, 0, 159.5, 0, 0, focal, 119.5, 0, 0, 0, 1, 0))


def test_a_90_degree_camera_has_a_focal_length_of_half_its_width():
    camera = intrinsics(CameraSettings(width=640, height=480, fov_deg=90.0))
    assert camera.fx == pytest.approx(320.0)


def test_the_vertical_fov_follows_from_the_aspect_ratio():
    settings = CameraSettings(width=320, height=240, fov_deg=60.0)
    expected = 2 * math.degrees(math.atan(math.tan(math.radians(30.0)) * 240 / 320))
    assert vertical_fov_deg(settings) == pytest.approx(expected)


@pytest.mark.parametrize(('field', 'value', 'parameter'), [
    ('width', 0, 'camera.width'),
    ('height', 2.5, 'camera.height'),
    ('fov_deg', 180.0, 'camera.fov_deg'),
    ('rate', 0.0, 'camera.rate'),
    ('near', -1.0, 'camera.near'),
    ('far', 0.001, 'camera.far'),
])
def test_bad_camera_settings_name_the_parameter(field, value, parameter):
    with pytest.raises(ParameterError, match=f"'{parameter}'"):
        CameraSettings(**{field: value})


# --- mounting -------------------------------------------------------------------

def test_the_camera_sits_at_the_tip_of_the_tilt_link_looking_along_its_z(pan_tilt_description):
    mount = camera_mount(pan_tilt_description.model, 'tilt_link',
                         {'pan_joint': 0.0, 'tilt_joint': HORIZONTAL_TILT})
    assert mount.translation == pytest.approx((0.0, 0.0, 0.2))  # half the 0.4 m cylinder
    # REP-103 optical frame in link axes: z forward = link z, y down = -link x
    # (link x points up when the tilt is horizontal), x right = link y.
    assert rotate(mount.rotation, (0, 0, 1)) == pytest.approx((0, 0, 1), abs=1e-12)
    assert rotate(mount.rotation, (0, 1, 0)) == pytest.approx((-1, 0, 0), abs=1e-12)
    assert rotate(mount.rotation, (1, 0, 0)) == pytest.approx((0, 1, 0), abs=1e-12)


def test_at_tilt_minus_pi_over_2_the_camera_looks_horizontally_and_upright(renderer):
    renderer.render([0.0, HORIZONTAL_TILT])
    eye, forward, up = renderer.optical_axes()
    assert eye == pytest.approx((-0.2, 0.0, 0.3), abs=1e-6)
    assert forward == pytest.approx((-1.0, 0.0, 0.0), abs=1e-6)
    assert up == pytest.approx((0.0, 0.0, 1.0), abs=1e-6)


def test_at_tilt_minus_pi_the_camera_looks_straight_down(renderer):
    renderer.render([0.0, -math.pi])
    _, forward, _ = renderer.optical_axes()
    assert forward == pytest.approx((0.0, 0.0, -1.0), abs=1e-6)


# --- what it sees ---------------------------------------------------------------

@pytest.mark.parametrize('target', TARGET_SET, ids=lambda target: target.name)
def test_facing_a_target_fills_the_image_centre_with_its_colour(renderer, target):
    image = as_array(renderer.render([pan_facing(target), HORIZONTAL_TILT]), renderer.settings)
    assert colour_mask(centre(image), target.rgba).mean() >= DOMINANT


@pytest.mark.parametrize('target', TARGET_SET, ids=lambda target: target.name)
def test_panning_away_from_a_target_takes_it_out_of_the_image(renderer, target):
    away = pan_facing(target) + (math.pi / 4 if pan_facing(target) < 0 else -math.pi / 4)
    image = as_array(renderer.render([away, HORIZONTAL_TILT]), renderer.settings)
    assert not colour_mask(image, target.rgba).any()


def test_the_image_is_upright_sky_above_ground_below(renderer):
    image = as_array(renderer.render([math.pi / 4, HORIZONTAL_TILT]), renderer.settings)
    assert image[0].min() == 255  # background above the horizon
    assert (image[-1] == GROUND_RGB).all()  # ground below


@pytest.mark.parametrize(('near', 'far'), [(0.1, 100.0), (0.05, 10.0), (0.02, 10.0)])
def test_the_ground_is_painted_whatever_the_clip_planes(renderer, pan_tilt_description, near, far):
    settings = CameraSettings(near=near, far=far)
    camera = Renderer(renderer.physics, pan_tilt_description.model, settings, 'targets')
    renderer.physics.reset_joints([math.pi / 4, HORIZONTAL_TILT - 0.3])
    image = as_array(camera.render(), settings)
    below = int(intrinsics(settings).cy) + 5  # the horizon is above the centre row
    assert (image[below:, 100] == GROUND_RGB).all()
    assert image[0].min() == 255  # and the sky stays background


def test_only_buffer_values_within_a_few_float32_steps_of_one_are_nothing_drawn():
    step = 2.0 ** -24
    buffer = numpy.array([1.0 + 2 * step, 1.0, 1.0 - step, 1.0 - 2 * step,
                          1.0 - 8 * step, 1.0 - 9 * step, 0.999, 0.5], dtype=numpy.float32)
    assert nothing_drawn(buffer).tolist() == [True] * 5 + [False] * 3


@pytest.mark.parametrize('down', [0.0, 0.2, -0.3])
def test_the_ground_meets_the_background_at_the_horizon_k_predicts(renderer, down):
    """Looking ``down`` rad below horizontal, the horizon is fy * tan(down) above cy."""
    image = as_array(renderer.render([math.pi / 4, HORIZONTAL_TILT - down]), renderer.settings)
    column = image[:, 100]  # a column with no target in it at pan pi/4
    ground_rows = numpy.nonzero((column == GROUND_RGB).all(axis=1))[0]
    camera = intrinsics(renderer.settings)
    horizon = camera.cy - camera.fy * math.tan(down)
    assert ground_rows.min() == pytest.approx(horizon, abs=1.0)
    assert (ground_rows == numpy.arange(ground_rows.min(), 240)).all()  # ground to the bottom


def test_looking_straight_down_the_camera_sees_only_the_yellow_base_disc(renderer):
    # From 0.1 m up, a 60 degree view spans 0.11 m of the 0.4 m wide base disc.
    image = as_array(renderer.render([0.0, -math.pi]), renderer.settings)
    assert colour_mask(image, (1.0, 1.0, 0.0, 1.0)).all()


def test_a_target_appears_where_the_camera_info_intrinsics_project_it(renderer):
    """K agrees with the rendered image: the red cube's silhouette is where K puts it."""
    red = TARGET_SET[0]
    pan = pan_facing(red) + math.radians(12.0)  # the cube off-centre, to the left
    image = as_array(renderer.render([pan, HORIZONTAL_TILT + math.radians(5.0)]),
                     renderer.settings)
    eye, forward, up = (numpy.array(v) for v in renderer.optical_axes())
    right = numpy.cross(forward, up)
    camera = intrinsics(renderer.settings)
    half = red.half_size
    corners = [numpy.array(red.position) + numpy.array((dx, dy, dz))
               for dx in (-half, half) for dy in (-half, half) for dz in (-half, half)]
    us, vs = [], []
    for corner in corners:
        ray = corner - eye
        depth = ray @ forward
        us.append(camera.cx + camera.fx * (ray @ right) / depth)
        vs.append(camera.cy + camera.fy * (ray @ -up) / depth)
    rows, columns = numpy.nonzero(colour_mask(image, red.rgba))
    # Pixel i covers [i - 0.5, i + 0.5]: the silhouette spans these pixel centres.
    assert columns.min() == pytest.approx(min(us) + 0.5, abs=1.5)
    assert columns.max() == pytest.approx(max(us) - 0.5, abs=1.5)
    assert rows.min() == pytest.approx(min(vs) + 0.5, abs=1.5)
    assert rows.max() == pytest.approx(max(vs) - 0.5, abs=1.5)


def test_an_empty_world_shows_only_the_robot(pan_tilt_description):
    renderer = Scene(pan_tilt_description, world='empty')
    try:
        image = as_array(renderer.render([0.0, HORIZONTAL_TILT]), renderer.settings)
    finally:
        renderer.close()
    assert image.min() == 255  # looking horizontally: nothing but background


# --- topics ---------------------------------------------------------------------

def test_images_and_camera_info_arrive_at_the_camera_rate_in_sim_time():
    with sim_node(**{'camera.rate': 10.0}) as harness:
        topic = harness.node.topic('camera', 'image_raw')
        images = harness.collect(Image, topic)
        infos = harness.collect(CameraInfo, harness.node.topic('camera', 'camera_info'))
        harness.wait_for_subscribers(topic)
        start = harness.simulation.time
        harness.run_until_sim_time(start + 2.0)
        assert harness.spin_until(lambda: len(images) >= 20 and len(infos) >= 20, budget_s=5.0)
    stamps = [m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in images]
    in_window = [s for s in stamps if start + 0.05 <= s < start + 1.05]
    assert len(in_window) == 10  # 10 Hz of sim time
    assert all(abs(s * 10 - round(s * 10)) < 1e-6 for s in stamps)  # on the 0.1 s grid
    image, info = images[-1], infos[-1]
    assert (image.width, image.height, image.encoding) == (320, 240, 'rgb8')
    assert image.step == 320 * 3 and len(image.data) == 320 * 240 * 3
    assert image.header.frame_id == info.header.frame_id == 'tilt_link_optical'
    assert list(info.k) == pytest.approx(intrinsics(CameraSettings()).k)
    assert list(info.p) == pytest.approx(intrinsics(CameraSettings()).p)
    assert (info.width, info.height) == (320, 240)


def test_panning_through_the_node_brings_a_target_in_and_out_of_view():
    blue = next(target for target in TARGET_SET if target.name == 'blue')
    assert pan_facing(blue) == 0.0  # the pan/tilt example's pan starts facing the blue target
    with sim_node() as harness:
        topic = harness.node.topic('camera', 'image_raw')
        images = harness.collect(Image, topic, qos=1)
        harness.wait_for_subscribers(topic)
        assert harness.spin_until(lambda: images)
        first = numpy.frombuffer(images[-1].data, numpy.uint8).reshape(240, 320, 3)
        assert colour_mask(centre(first), blue.rgba).mean() >= DOMINANT

        start = harness.command_position('joint1_position_controller', 0.8)
        harness.run_until_sim_time(start + 9.5, budget_s=60.0)  # 8 s ramp at 0.1 rad/s
        assert harness.simulation.joint_positions()['pan_joint'] == pytest.approx(0.8, abs=0.02)
        count = len(images)
        assert harness.spin_until(lambda: len(images) > count)
        last = numpy.frombuffer(images[-1].data, numpy.uint8).reshape(240, 320, 3)
    assert not colour_mask(last, blue.rgba).any()


def test_frames_keep_coming_after_reset_simulation():
    # Sim time goes back to 0: the camera's schedule must start again, not
    # wait until sim time passes the frame that was due before the reset.
    with sim_node(**{'camera.rate': 10.0}) as harness:
        topic = harness.node.topic('camera', 'image_raw')
        images = harness.collect(Image, topic)
        harness.wait_for_subscribers(topic)
        harness.run_until_sim_time(2.0)
        harness.node.set_paused(True)
        harness.call(Empty, 'reset_simulation')
        assert harness.simulation.time == 0.0
        harness.drain()
        count = len(images)
        harness.node.set_paused(False)
        harness.run_for(1.2)
        stamps = [m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in images[count:]]
    assert len([s for s in stamps if s <= 1.2 + 1e-6]) >= 12, stamps  # ~12 frames at 10 Hz


def test_nothing_is_rendered_while_nobody_watches():
    with sim_node() as harness:
        harness.run_until_sim_time(1.0)
        assert harness.node.features.camera.frames == 0


def test_camera_enabled_false_publishes_no_camera_topics():
    with sim_node(**{'camera.enabled': False}) as harness:
        published, _subscribed = harness.own_topics()
        assert harness.node.topic('camera', 'image_raw') not in published
        assert harness.node.topic('joint_states') in published  # the look-up sees topics
        assert harness.node.features.camera is None


def test_a_camera_on_a_link_the_robot_lacks_is_off_by_default():
    with sim_node(**{'camera.link': 'no_such_link'}) as harness:
        assert harness.node.features.camera is None


def test_enabling_a_camera_on_a_missing_link_is_an_error_naming_the_parameter():
    with pytest.raises(ParameterError, match="'camera.link'.*no_such_link.*tilt_link"), \
            sim_node(**{'camera.link': 'no_such_link', 'camera.enabled': True}):
        pass


def test_an_unknown_world_is_an_error_naming_the_choices():
    with pytest.raises(ParameterError, match="'world'.*empty, ground, targets"), \
            sim_node(world='moon'):
        pass


def test_an_integer_fov_is_accepted():
    with sim_node(**{'camera.fov_deg': 90}) as harness:
        assert harness.node.features.camera.settings.fov_deg == 90.0


def test_on_the_root_link_the_camera_sits_on_its_frame_not_its_centre_of_mass(tmp_path):
    # PyBullet reports a body's base by its centre of mass, here 0.3 m from the link frame.
    urdf = tmp_path / 'offset.urdf'
    urdf.write_text(
        '<robot name="offset"><link name="base_link"><inertial><origin xyz="0.3 0 0.1"/>'
        '<mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
        '</inertial><visual><geometry><box size="0.1 0.1 0.2"/></geometry></visual></link>'
        '<joint name="spin" type="revolute"><parent link="base_link"/><child link="arm"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        '<link name="arm"><inertial><mass value="0.1"/>'
        '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>'
        '</link></robot>', encoding='utf-8')
    description = load_description(urdf)
    physics = Physics(description, 0.001)
    try:
        renderer = Renderer(physics, description.model, CameraSettings(link='base_link'), 'empty')
        frame = renderer.link_pose()
        assert frame.translation == pytest.approx(physics.base_frame().translation, abs=1e-9)
        assert frame.translation == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
    finally:
        physics.close()
