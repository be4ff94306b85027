"""Sensor tags: what the parser reads, and the topics and frames each plugin convention gives."""

import math
import pathlib

import pytest
from sensor_fixtures import sensor_rig_urdf

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.sensors import (
    CHILD_TO_PARENT,
    GZ,
    PARENT,
    PARENT_TO_CHILD,
    ROS1,
    ROS2,
    SensorKind,
    data_frame,
    sensor_interface,
)
from pan_tilt_sim.model.transforms import rotate
from pan_tilt_sim.model.urdf import parse_urdf

SOURCE = pathlib.Path('robot.urdf')


def robot(*gazebo: str, extra_links: str = '') -> str:
    """Return a two-link URDF (base_link, arm on joint 'elbow') with ``gazebo`` blocks."""
    return f"""<robot name="bot">
      <link name="base_link"/>
      <link name="arm"/>
      {extra_links}
      <joint name="elbow" type="revolute"><parent link="base_link"/><child link="arm"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      {''.join(gazebo)}
    </robot>"""


def sensor_block(reference: str, sensor_type: str, body: str = '', plugin: str = '',
                 name: str = 'sensor') -> str:
    return (f'<gazebo reference="{reference}"><sensor type="{sensor_type}" name="{name}">'
            f'{body}{plugin}</sensor></gazebo>')


RAY = ('<ray><scan><horizontal><samples>5</samples><min_angle>-1</min_angle>'
       '<max_angle>1</max_angle></horizontal></scan><range><min>0.1</min><max>10</max>'
       '</range></ray>')


def only_sensor(urdf: str):
    model = parse_urdf(urdf, SOURCE)
    assert len(model.sensors) == 1, model.sensor_warnings
    return model, model.sensors[0]


def interface(urdf: str, override: str = ''):
    model, sensor = only_sensor(urdf)
    return sensor_interface(sensor, model.name, override)


# --- the fixture: one sensor of each kind --------------------------------------------------

def test_the_rig_declares_one_sensor_of_each_kind_and_two_it_cannot_simulate():
    model = parse_urdf(sensor_rig_urdf(), SOURCE)
    kinds = {sensor.name: sensor.kind for sensor in model.sensors}
    assert kinds == {'depth_camera': SensorKind.DEPTH, 'laser': SensorKind.LIDAR,
                     'imu': SensorKind.IMU, 'ft': SensorKind.FORCE_TORQUE}
    assert len(model.sensor_warnings) == 2
    assert "sensor 'gps' (type 'gps') skipped" in model.sensor_warnings[0]
    assert "sensor 'bumper' (type 'contact') skipped" in model.sensor_warnings[1]


def test_the_rig_sensors_read_their_tags():
    model = parse_urdf(sensor_rig_urdf(), SOURCE)
    sensors = {sensor.name: sensor for sensor in model.sensors}
    camera = sensors['depth_camera'].camera
    assert (camera.width, camera.height, camera.horizontal_fov) == (64, 48, 1.2)
    assert (camera.near, camera.far) == (0.05, 20.0)
    assert sensors['depth_camera'].colour  # Gazebo classic's depth sensor renders colour
    ray = sensors['laser'].ray
    assert ray.horizontal.count == 121 and ray.rows == 1
    assert (ray.range_min, ray.range_max, ray.range_resolution) == (0.1, 5.0, 0.01)
    ft = sensors['ft']
    assert (ft.joint, ft.link, ft.parent_link) == ('hang_joint', 'weight', 'base_link')
    assert ft.force_torque.measure_direction == PARENT_TO_CHILD
    assert sensors['imu'].update_rate == 200.0


# --- ROS 1 conventions -------------------------------------------------------------------------

def test_ros1_camera_topics_are_robot_namespace_camera_name_topic():
    plugin = ('<plugin name="c" filename="libgazebo_ros_camera.so">'
              '<robotNamespace>/bot</robotNamespace><cameraName>cam</cameraName>'
              '<imageTopicName>rgb/image</imageTopicName><frameName>arm_optical</frameName>'
              '</plugin>')
    found = interface(robot(sensor_block('arm', 'camera', plugin=plugin)))
    assert found.convention == ROS1
    assert dict(found.topics) == {'image': '/bot/cam/rgb/image',
                                  'camera_info': '/bot/cam/camera_info'}
    assert found.frame_id == 'arm_optical'


def test_ros1_openni_kinect_defaults():
    plugin = ('<plugin name="k" filename="libgazebo_ros_openni_kinect.so">'
              '<cameraName>kinect</cameraName></plugin>')
    found = interface(robot(sensor_block('arm', 'depth', plugin=plugin)))
    assert dict(found.topics) == {
        'image': '/kinect/ir/image_raw', 'camera_info': '/kinect/ir/camera_info',
        'depth': '/kinect/depth/image_raw', 'depth_info': '/kinect/depth/camera_info',
        'points': '/kinect/points'}
    assert found.depth_range == (0.4, 5.0)  # pointCloudCutoff, pointCloudCutoffMax
    assert found.frame_id == 'arm'  # Gazebo leaves it empty; the link is what users mean


def test_ros1_laser_topic_is_resolved_in_the_robot_namespace_and_absolute_names_stay():
    plugin = ('<plugin name="l" filename="libgazebo_ros_laser.so">'
              '<robotNamespace>bot</robotNamespace><topicName>{}</topicName></plugin>')
    relative = interface(robot(sensor_block('arm', 'ray', RAY, plugin.format('laser/scan'))))
    absolute = interface(robot(sensor_block('arm', 'ray', RAY, plugin.format('/scan'))))
    assert relative.topics == {'scan': '/bot/laser/scan'}
    assert absolute.topics == {'scan': '/scan'}


def test_ros1_laser_without_topic_name_publishes_on_world_as_gazebo_does():
    plugin = '<plugin name="l" filename="libgazebo_ros_gpu_laser.so"/>'
    found = interface(robot(sensor_block('arm', 'gpu_ray', RAY, plugin)))
    assert found.topics == {'scan': '/world'}
    assert found.frame_id == 'arm'  # its frame default, '/world', would not move with the link


def test_ros1_imu_sensor_defaults_to_the_model_namespace_imu_data_and_1_hz():
    plugin = ('<plugin name="i" filename="libgazebo_ros_imu_sensor.so">'
              '<frameName>arm</frameName><gaussianNoise>0.01</gaussianNoise></plugin>')
    found = interface(robot(sensor_block('arm', 'imu', '<update_rate>100</update_rate>',
                                         plugin)))
    assert found.topics == {'imu': '/bot/imu_data'}
    assert found.rate == 1.0  # updateRateHZ's default throttles the 100 Hz sensor
    assert found.noise_stddev == 0.01
    assert not found.orientation_from_start  # REP 145 unless initialOrientationAsReference


def test_ros1_imu_sensor_without_frame_name_is_skipped_as_gazebo_stops_it():
    plugin = '<plugin name="i" filename="libgazebo_ros_imu_sensor.so"><topicName>imu</topicName>'\
        '</plugin>'
    model = parse_urdf(robot(sensor_block('arm', 'imu', plugin=plugin)), SOURCE)
    assert model.sensors == ()
    assert 'needs <frameName>' in model.sensor_warnings[0]


def test_ros1_ft_model_plugin_reports_the_childs_wrench_in_the_child_frame():
    plugin = ('<gazebo><plugin name="ft" filename="libgazebo_ros_ft_sensor.so">'
              '<robotNamespace>/bot</robotNamespace><jointName>elbow</jointName>'
              '<topicName>ft_sensor_topic</topicName><updateRate>100</updateRate></plugin>'
              '</gazebo>')
    model, sensor = only_sensor(robot(plugin))
    found = sensor_interface(sensor, model.name)
    assert found.topics == {'wrench': '/bot/ft_sensor_topic'}
    assert (found.frame_id, found.rate) == ('arm', 100.0)
    assert found.measure_direction == PARENT_TO_CHILD  # JointWrench body2Force


def test_a_node_namespace_replaces_the_plugin_namespace_as_spawn_robot_namespace_does():
    plugin = ('<plugin name="l" filename="libgazebo_ros_laser.so">'
              '<robotNamespace>/bot</robotNamespace><topicName>scan</topicName></plugin>')
    found = interface(robot(sensor_block('arm', 'ray', RAY, plugin)), override='/left')
    assert found.topics == {'scan': '/left/scan'}


# --- ROS 2 conventions -------------------------------------------------------------------------

def test_ros2_camera_defaults_to_the_sensor_name_at_the_root_and_the_link_frame():
    plugin = '<plugin name="driver" filename="libgazebo_ros_camera.so"><ros/></plugin>'
    found = interface(robot(sensor_block('arm', 'camera', plugin=plugin, name='eye')))
    assert found.convention == ROS2
    assert dict(found.topics) == {'image': '/eye/image_raw', 'camera_info': '/eye/camera_info'}
    assert found.frame_id == 'arm'


def test_ros2_depth_camera_topics_under_the_namespace_and_its_depth_range():
    plugin = ('<plugin name="driver" filename="libgazebo_ros_camera.so">'
              '<ros><namespace>demo</namespace></ros><camera_name>cam</camera_name>'
              '<frame_name>cam_optical</frame_name><max_depth>8</max_depth></plugin>')
    found = interface(robot(sensor_block('arm', 'depth', plugin=plugin)))
    assert dict(found.topics) == {
        'image': '/demo/cam/image_raw', 'camera_info': '/demo/cam/camera_info',
        'depth': '/demo/cam/depth/image_raw', 'depth_info': '/demo/cam/depth/camera_info',
        'points': '/demo/cam/points'}
    assert found.depth_range == (0.4, 8.0)  # min_depth's default is 0.4 m
    assert found.frame_id == 'cam_optical'


def test_ros2_ray_sensor_publishes_on_tilde_out_unless_remapped():
    plugin = ('<plugin name="lidar" filename="libgazebo_ros_ray_sensor.so">'
              '<ros><namespace>/demo</namespace>{}</ros>'
              '<output_type>sensor_msgs/LaserScan</output_type></plugin>')
    plain = interface(robot(sensor_block('arm', 'ray', RAY, plugin.format(''))))
    remapped = interface(robot(sensor_block(
        'arm', 'ray', RAY, plugin.format('<remapping>~/out:=scan</remapping>'))))
    absolute = interface(robot(sensor_block(
        'arm', 'ray', RAY, plugin.format('<argument>~/out:=/laser</argument>'))))
    assert plain.topics == {'scan': '/demo/lidar/out'}
    assert remapped.topics == {'scan': '/demo/scan'}
    assert absolute.topics == {'scan': '/laser'}


def test_ros2_ray_sensor_defaults_to_a_point_cloud():
    plugin = '<plugin name="lidar" filename="libgazebo_ros_ray_sensor.so"/>'
    assert interface(robot(sensor_block('arm', 'ray', RAY, plugin))).topics == {
        'points': '/lidar/out'}


def test_ros2_imu_on_tilde_out_with_its_frame_name():
    plugin = ('<plugin name="imu_plugin" filename="libgazebo_ros_imu_sensor.so">'
              '<ros><namespace>/demo</namespace><remapping>~/out:=imu</remapping></ros>'
              '<frame_name>imu_frame</frame_name></plugin>')
    found = interface(robot(sensor_block('arm', 'imu', plugin=plugin)))
    assert (found.topics, found.frame_id) == ({'imu': '/demo/imu'}, 'imu_frame')


def test_ros2_ft_model_plugin_publishes_wrench_in_its_namespace():
    plugin = ('<gazebo><plugin name="ft" filename="libgazebo_ros_ft_sensor.so">'
              '<ros><namespace>/demo</namespace></ros><joint_name>elbow</joint_name>'
              '<update_rate>25</update_rate><gaussian_noise>0.1</gaussian_noise></plugin>'
              '</gazebo>')
    model, sensor = only_sensor(robot(plugin))
    found = sensor_interface(sensor, model.name)
    assert found.topics == {'wrench': '/demo/wrench'}
    assert (found.frame_id, found.rate, found.noise_stddev) == ('arm', 25.0, 0.1)


# --- gz-sim (no plugin) ------------------------------------------------------------------------

def test_gz_sensors_use_their_topic_as_ros_gz_bridge_carries_it():
    lidar = interface(robot(sensor_block('arm', 'gpu_lidar', RAY + '<topic>lidar</topic>')))
    assert lidar.convention == GZ
    assert lidar.topics == {'scan': '/lidar', 'points': '/lidar/points'}
    assert lidar.frame_id == 'sensor'  # gz's default frame id: the sensor's name
    rgbd = interface(robot(sensor_block('arm', 'rgbd_camera', '<topic>rgbd</topic>'
                                        '<gz_frame_id>arm</gz_frame_id>')))
    assert dict(rgbd.topics) == {
        'image': '/rgbd/image', 'depth': '/rgbd/depth_image', 'camera_info': '/rgbd/camera_info',
        'depth_info': '/rgbd/camera_info', 'points': '/rgbd/points'}
    assert rgbd.frame_id == 'arm'
    camera = interface(robot(sensor_block('arm', 'camera', '<topic>cam/image</topic>')))
    assert dict(camera.topics) == {'image': '/cam/image', 'camera_info': '/cam/camera_info'}


def test_gz_sensor_without_a_topic_gets_gz_default_topic():
    found = interface(robot(sensor_block('arm', 'imu', name='imu0')))
    assert found.topics == {'imu': '/world/default/model/bot/link/arm/sensor/imu0/imu'}


def test_gz_depth_camera_has_no_colour():
    model, sensor = only_sensor(robot(sensor_block('arm', 'depth_camera', '<topic>d</topic>')))
    assert not sensor.colour
    assert dict(sensor_interface(sensor, model.name).topics) == {
        'depth': '/d', 'depth_info': '/camera_info', 'points': '/d/points'}


def test_force_torque_sensor_on_a_joint_measures_as_its_tag_says():
    body = ('<topic>ft</topic><force_torque><frame>parent</frame>'
            '<measure_direction>child_to_parent</measure_direction></force_torque>')
    model, sensor = only_sensor(robot(sensor_block('elbow', 'force_torque', body)))
    found = sensor_interface(sensor, model.name)
    assert (sensor.joint, sensor.link) == ('elbow', 'arm')
    assert (found.wrench_frame, found.measure_direction) == (PARENT, CHILD_TO_PARENT)


# --- what the parser reads ---------------------------------------------------------------------

def test_sensor_pose_places_the_sensor_and_cameras_look_along_its_x():
    body = '<pose>0.1 0.2 0.3 0 0 1.5707963267948966</pose><topic>c</topic>'
    _, sensor = only_sensor(robot(sensor_block('arm', 'camera', body)))
    assert sensor.pose.translation == (0.1, 0.2, 0.3)
    optical = data_frame(sensor)
    # The sensor is yawed 90 degrees: it looks along the link's +y, its up is +z.
    assert rotate(optical.rotation, (0, 0, 1)) == pytest.approx((0, 1, 0), abs=1e-12)
    assert rotate(optical.rotation, (0, 1, 0)) == pytest.approx((0, 0, -1), abs=1e-12)
    assert rotate(optical.rotation, (1, 0, 0)) == pytest.approx((1, 0, 0), abs=1e-12)


def test_noise_per_axis_and_the_old_sdf_style():
    new = ('<imu><angular_velocity><z><noise type="gaussian"><mean>0.1</mean>'
           '<stddev>0.02</stddev><bias_mean>0.5</bias_mean></noise></z></angular_velocity></imu>')
    old = ('<imu><noise><type>gaussian</type><rate><stddev>0.03</stddev></rate>'
           '<accel><stddev>0.4</stddev></accel></noise></imu>')
    _, first = only_sensor(robot(sensor_block('arm', 'imu', new)))
    _, second = only_sensor(robot(sensor_block('arm', 'imu', old)))
    z = first.imu.angular_velocity_noise[2]
    assert (z.mean, z.stddev, z.bias_mean) == (0.1, 0.02, 0.5)
    assert first.imu.angular_velocity_noise[0].is_zero
    assert [noise.stddev for noise in second.imu.angular_velocity_noise] == [0.03] * 3
    assert [noise.stddev for noise in second.imu.linear_acceleration_noise] == [0.4] * 3


def test_scan_count_is_samples_times_resolution_and_angles_span_min_to_max():
    body = RAY.replace('<samples>5</samples>', '<samples>5</samples><resolution>2</resolution>')
    _, sensor = only_sensor(robot(sensor_block('arm', 'ray', body + '<topic>s</topic>')))
    angles = sensor.ray.horizontal.angles()
    assert len(angles) == 10
    assert (angles[0], angles[-1]) == (-1.0, 1.0)
    assert sensor.ray.horizontal.increment == pytest.approx(2.0 / 9)


@pytest.mark.parametrize(('what', 'where'), [
    ('<gazebo reference="nowhere"><sensor type="imu" name="s"/></gazebo>', "'nowhere'"),
    ('<gazebo reference="elbow"><sensor type="imu" name="s"/></gazebo>', 'joint'),
    ('<gazebo reference="arm"><sensor type="force_torque" name="s"/></gazebo>', 'joint'),
    ('<gazebo reference="arm"><sensor type="sonar" name="s"/></gazebo>', "'sonar'"),
    ('<gazebo><sensor type="imu" name="s"/></gazebo>', 'reference'),
    ('<gazebo reference="arm"><sensor type="camera" name="s">'
     '<plugin name="p" filename="libgazebo_ros_multicamera.so"/></sensor></gazebo>',
     'libgazebo_ros_multicamera.so'),
    ('<gazebo reference="arm"><sensor type="ray" name="s">' + RAY +
     '<plugin name="p" filename="libgazebo_ros_ray_sensor.so"><output_type>sensor_msgs/Range'
     '</output_type></plugin></sensor></gazebo>', 'Range'),
    ('<gazebo><plugin name="p" filename="libgazebo_ros_imu.so"/></gazebo>', 'imu_sensor'),
])
def test_a_sensor_that_cannot_be_simulated_is_skipped_with_one_warning_naming_it(what, where):
    model = parse_urdf(robot(what), SOURCE)
    assert model.sensors == ()
    assert len(model.sensor_warnings) == 1
    assert where in model.sensor_warnings[0]
    assert str(SOURCE) in model.sensor_warnings[0]


@pytest.mark.parametrize(('body', 'message'), [
    ('<camera><horizontal_fov>fast</horizontal_fov></camera>', 'horizontal_fov'),
    ('<camera><horizontal_fov>3.5</horizontal_fov></camera>', 'horizontal_fov'),
    ('<camera><image><width>0</width></image></camera>', 'image/width'),
    ('<camera><clip><near>2</near><far>1</far></clip></camera>', '<clip>'),
    ('<update_rate>-1</update_rate>', 'update_rate'),
    ('<pose>1 2 3</pose>', '<pose>'),
    ('<camera><noise><type>gaussian</type><stddev>-1</stddev></noise></camera>', 'stddev'),
])
def test_malformed_camera_tags_end_start_up_naming_the_sensor_and_element(body, message):
    with pytest.raises(DescriptionError, match=f"sensor 'cam'.*{message}"):
        parse_urdf(robot(sensor_block('arm', 'camera', body, name='cam')), SOURCE)


def test_a_ray_sensor_needs_a_range():
    body = RAY.replace('<max>10</max>', '<max>0.05</max>')
    with pytest.raises(DescriptionError, match='<range> needs 0 <= min < max'):
        parse_urdf(robot(sensor_block('arm', 'ray', body)), SOURCE)


def test_a_bad_plugin_number_ends_start_up():
    plugin = ('<plugin name="d" filename="libgazebo_ros_camera.so"><min_depth>near</min_depth>'
              '</plugin>')
    with pytest.raises(DescriptionError, match='min_depth'):
        parse_urdf(robot(sensor_block('arm', 'depth', plugin=plugin)), SOURCE)


def test_a_robot_without_sensor_tags_has_none():
    model = parse_urdf(robot(), SOURCE)
    assert model.sensors == () and model.sensor_warnings == ()


def test_camera_focal_length_follows_the_horizontal_fov():
    _, sensor = only_sensor(robot(sensor_block(
        'arm', 'camera', '<camera><horizontal_fov>1.5707963267948966</horizontal_fov>'
        '<image><width>640</width><height>480</height></image></camera>')))
    assert sensor.camera.focal_length == pytest.approx(320.0)
    assert sensor.camera.vertical_fov == pytest.approx(2 * math.atan(0.75))


# --- sizes and angles within their limits ------------------------------------------------

@pytest.mark.parametrize(('body', 'problem'), [
    pytest.param(RAY.replace('<samples>5<', '<samples>10000000<'),
                 '<horizontal> 10000000 samples x resolution 1 is more than the limit of 262144 '
                 'beams per scan (the densest real lidars: 128 channels x 2048 columns)',
                 id='ten million samples'),
    pytest.param(RAY.replace('<samples>5<', '<samples>1e308<').replace(
        '<min_angle>', '<resolution>10</resolution><min_angle>'),
                 'samples x resolution 10 is more than the limit of 262144',
                 id='a count that overflows a float'),
    pytest.param(RAY.replace('</horizontal>', '</horizontal><vertical><samples>1000</samples>'
                             '<min_angle>-0.5</min_angle><max_angle>0.5</max_angle></vertical>'
                             ).replace('<samples>5<', '<samples>1000<'),
                 '1000 x 1000 = 1000000 beams per scan is more than the limit of 262144',
                 id='rows times columns'),
    pytest.param(RAY.replace('<max_angle>1<', '<max_angle>1e300<'),
                 '<horizontal><max_angle> 1e+300 rad is beyond +-2 pi', id='max_angle 1e300'),
    pytest.param(RAY.replace('<min_angle>-1<', '<min_angle>-7<'),
                 '<horizontal><min_angle> -7 rad is beyond +-2 pi', id='min_angle -7'),
    pytest.param(RAY.replace('<min_angle>-1<', '<min_angle>1<'),
                 '<horizontal> needs min_angle < max_angle for 5 beams, got min_angle 1, '
                 'max_angle 1', id='five beams at one angle'),
    pytest.param(RAY.replace('<min_angle>-1<', '<min_angle>2<'),
                 '<horizontal> needs min_angle < max_angle', id='min above max'),
])
def test_a_scan_beyond_its_limits_ends_start_up_naming_the_sensor_and_limit(body, problem):
    with pytest.raises(DescriptionError) as raised:
        parse_urdf(robot(sensor_block('arm', 'ray', body, name='laser')), SOURCE)
    assert str(raised.value).startswith(f"{SOURCE}: sensor 'laser': ")
    assert problem in str(raised.value)


def test_a_scan_at_its_limits_and_a_single_beam_at_one_angle_are_taken():
    full = RAY.replace('<samples>5<', '<samples>2048<').replace(
        '</horizontal>', '</horizontal><vertical><samples>128</samples><min_angle>-0.3'
        '</min_angle><max_angle>0.3</max_angle></vertical>').replace(
        '<min_angle>-1<', '<min_angle>-6.283185307179586<').replace(
        '<max_angle>1<', '<max_angle>6.283185307179586<')
    _, sensor = only_sensor(robot(sensor_block('arm', 'ray', full)))
    assert sensor.ray.horizontal.count * sensor.ray.vertical.count == 262144
    one = RAY.replace('<samples>5<', '<samples>1<').replace('<min_angle>-1<', '<min_angle>1<')
    _, sensor = only_sensor(robot(sensor_block('arm', 'ray', one)))
    assert sensor.ray.horizontal.angles() == (1.0,)


@pytest.mark.parametrize(('width', 'height', 'problem'), [
    (100000, 100000, '100000 x 100000 = 10000000000 pixels per image is more than the limit of '
     "8294400 (4K UHD (3840 x 2160): what PyBullet's CPU renderer draws"),
    (3841, 2160, '3841 x 2160 = 8296560 pixels per image'),
    (8294401, 1, '8294401 x 1 = 8294401 pixels'),
])
def test_an_image_beyond_4k_ends_start_up_naming_the_sensor_and_limit(width, height, problem):
    body = f'<camera><image><width>{width}</width><height>{height}</height></image></camera>'
    with pytest.raises(DescriptionError) as raised:
        parse_urdf(robot(sensor_block('arm', 'camera', body, name='cam')), SOURCE)
    assert str(raised.value).startswith(f"{SOURCE}: sensor 'cam': ")
    assert problem in str(raised.value)


def test_a_4k_image_is_taken():
    body = '<camera><image><width>3840</width><height>2160</height></image></camera>'
    _, sensor = only_sensor(robot(sensor_block('arm', 'camera', body)))
    assert (sensor.camera.width, sensor.camera.height) == (3840, 2160)


def test_a_sensor_rate_whose_period_overflows_ends_start_up():
    with pytest.raises(DescriptionError, match=r"sensor 'cam': <update_rate> 5e-324 must be a "
                                               'rate > 0 Hz'):
        parse_urdf(robot(sensor_block('arm', 'camera', '<update_rate>5e-324</update_rate>',
                                      name='cam')), SOURCE)


@pytest.mark.parametrize(('clip', 'problem'), [
    ('<clip><near>0.1</near><far>1e300</far></clip>',
     '<clip> far / near = 1e+301 is more than the limit of 1e+06'),
    ('<clip><near>1e-300</near><far>0.05</far></clip>', '<clip> far / near = 5e+298'),
    ('<clip><near>0.1</near><far>10</far></clip><depth_camera><clip><near>1e-9</near>'
     '<far>10</far></clip></depth_camera>', '<depth_camera><clip> far / near = 1e+10'),
])
def test_clip_planes_a_depth_buffer_cannot_hold_end_start_up(clip, problem):
    with pytest.raises(DescriptionError) as raised:
        parse_urdf(robot(sensor_block('arm', 'camera', f'<camera>{clip}</camera>', name='cam')),
                   SOURCE)
    assert str(raised.value).startswith(f"{SOURCE}: sensor 'cam': ")
    assert problem in str(raised.value)
