"""A test rig with one sensor of each kind, each in front of a known truth.

``sensor_rig`` (fixed base at the origin, world ``empty`` in the tests):

* a wall -- a fixed link, a thin box -- whose front face is the plane
  x = ``WALL_X``, 3 m wide and 3 m high around z = 1;
* a **depth camera** at (0, 0, 1) looking along +x at the wall, declared
  the ROS 2 way (``libgazebo_ros_camera.so``, namespace ``/rig``,
  camera_name ``front``, frame_name ``front_optical``, a frame the URDF
  does not declare);
* a **lidar** at (0, 0, ``LIDAR_Z``) scanning +-``LIDAR_HALF_ANGLE`` around +x,
  declared the ROS 1 way (``libgazebo_ros_laser.so``, robotNamespace
  ``/rig``, topicName ``scan``, frameName ``lidar_link``): its centre beam
  meets the wall, its outer beams pass the wall's edges and see nothing;
* an **IMU** ``IMU_RADIUS`` from the axis of a continuous joint about z
  (``spin_joint``, a velocity controller), declared the gz way (``<topic>``,
  ``<gz_frame_id>``);
* a **force-torque** sensor on the fixed joint holding a ``HANG_MASS`` kg
  weight, its centre of mass ``HANG_DROP`` below the joint, declared with a
  ROS 2 ``libgazebo_ros_ft_sensor.so`` (namespace ``/rig``, ``wrench:=ft``),
  measuring parent-to-child in the child frame;
* two sensors the simulator does not model (a gps, a contact sensor), each
  skipped with one warning.
"""

from __future__ import annotations

import pathlib
import textwrap

WALL_X = 2.0  # m: the wall's front face
WALL_HALF = 1.5  # m: half its width and height
CAMERA_Z = 1.0
LIDAR_Z = 1.3
LIDAR_HALF_ANGLE = 1.2  # rad
LIDAR_SAMPLES = 121  # odd: one beam straight ahead
LIDAR_RESOLUTION = 0.01  # m, the declared range resolution
LIDAR_MAX = 5.0
IMU_RADIUS = 0.5  # m from the spin axis
HANG_MASS = 2.0  # kg
HANG_DROP = 0.2  # m
DEPTH_WIDTH, DEPTH_HEIGHT = 64, 48
DEPTH_FOV = 1.2  # rad
IMU_RATE = 200.0  # Hz: above the /clock rate, so sim_node must stop between /clock messages
NAMESPACE = '/rig'

TOPICS = {
    'depth': '/rig/front/depth/image_raw',
    'depth_info': '/rig/front/depth/camera_info',
    'image': '/rig/front/image_raw',
    'camera_info': '/rig/front/camera_info',
    'points': '/rig/front/points',
    'scan': '/rig/scan',
    'imu': '/imu',
    'wrench': '/rig/ft',
}
FRAMES = {'depth': 'front_optical', 'scan': 'lidar_link', 'imu': 'imu_link',
          'wrench': 'weight'}


def _inertial(mass: float, z: float = 0.0) -> str:
    return (f'<inertial><origin xyz="0 0 {z}"/><mass value="{mass}"/>'
            '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>')


def _fixed(name: str, parent: str, child: str, xyz: str) -> str:
    return (f'<joint name="{name}" type="fixed"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}"/></joint>')


def sensor_rig_urdf() -> str:
    """Return the rig's URDF."""
    wall = (f'<geometry><box size="0.02 {2 * WALL_HALF} {2 * WALL_HALF}"/></geometry>')
    return textwrap.dedent(f"""\
        <?xml version="1.0"?>
        <robot name="sensor_rig">
          <link name="base_link">{_inertial(10.0)}</link>
          {_fixed('wall_joint', 'base_link', 'wall', f'{WALL_X + 0.01} 0 {CAMERA_Z}')}
          <link name="wall">{_inertial(1.0)}
            <visual>{wall}</visual><collision>{wall}</collision></link>
          {_fixed('camera_joint', 'base_link', 'camera_link', f'0 0 {CAMERA_Z}')}
          <link name="camera_link">{_inertial(0.1)}</link>
          {_fixed('lidar_joint', 'base_link', 'lidar_link', f'0 0 {LIDAR_Z}')}
          <link name="lidar_link">{_inertial(0.1)}</link>
          <joint name="spin_joint" type="continuous">
            <parent link="base_link"/><child link="spinner"/>
            <origin xyz="0 -3 0.5"/><axis xyz="0 0 1"/>
            <limit effort="100" velocity="10"/><dynamics damping="0.0" friction="0.0"/>
          </joint>
          <link name="spinner">{_inertial(1.0)}</link>
          {_fixed('imu_joint', 'spinner', 'imu_link', f'{IMU_RADIUS} 0 0')}
          <link name="imu_link">{_inertial(0.1)}</link>
          {_fixed('hang_joint', 'base_link', 'weight', '0 3 1')}
          <link name="weight">{_inertial(HANG_MASS, -HANG_DROP)}</link>

          <gazebo reference="camera_link">
            <sensor type="depth" name="depth_camera">
              <update_rate>10</update_rate>
              <camera>
                <horizontal_fov>{DEPTH_FOV}</horizontal_fov>
                <image><width>{DEPTH_WIDTH}</width><height>{DEPTH_HEIGHT}</height>
                  <format>R8G8B8</format></image>
                <clip><near>0.05</near><far>20</far></clip>
              </camera>
              <plugin name="depth_driver" filename="libgazebo_ros_camera.so">
                <ros><namespace>{NAMESPACE}</namespace></ros>
                <camera_name>front</camera_name>
                <frame_name>front_optical</frame_name>
                <min_depth>0.1</min_depth>
                <max_depth>10</max_depth>
              </plugin>
            </sensor>
          </gazebo>
          <gazebo reference="lidar_link">
            <sensor type="ray" name="laser">
              <update_rate>20</update_rate>
              <ray>
                <scan><horizontal><samples>{LIDAR_SAMPLES}</samples><resolution>1</resolution>
                  <min_angle>-{LIDAR_HALF_ANGLE}</min_angle><max_angle>{LIDAR_HALF_ANGLE}</max_angle>
                </horizontal></scan>
                <range><min>0.1</min><max>{LIDAR_MAX}</max>
                  <resolution>{LIDAR_RESOLUTION}</resolution></range>
              </ray>
              <plugin name="laser_driver" filename="libgazebo_ros_laser.so">
                <robotNamespace>{NAMESPACE}</robotNamespace>
                <topicName>scan</topicName>
                <frameName>lidar_link</frameName>
              </plugin>
            </sensor>
          </gazebo>
          <gazebo reference="imu_link">
            <sensor type="imu" name="imu">
              <update_rate>{IMU_RATE}</update_rate>
              <topic>imu</topic>
              <gz_frame_id>imu_link</gz_frame_id>
            </sensor>
          </gazebo>
          <gazebo reference="hang_joint">
            <sensor type="force_torque" name="ft">
              <update_rate>50</update_rate>
              <force_torque><frame>child</frame>
                <measure_direction>parent_to_child</measure_direction></force_torque>
              <plugin name="ft_driver" filename="libgazebo_ros_ft_sensor.so">
                <ros><namespace>{NAMESPACE}</namespace><remapping>wrench:=ft</remapping></ros>
              </plugin>
            </sensor>
          </gazebo>
          <gazebo reference="base_link">
            <sensor type="gps" name="gps"><update_rate>1</update_rate></sensor>
            <sensor type="contact" name="bumper"/>
          </gazebo>
        </robot>
        """)


CONTROLLERS_YAML = """\
joint_state_controller:
  type: joint_state_controller/JointStateController
  publish_rate: 50
spin_controller:
  type: velocity_controllers/JointVelocityController
  joint: spin_joint
  pid: {p: 20.0, i: 0.0, d: 0.0}
"""


def write_sensor_rig(folder: pathlib.Path) -> tuple[pathlib.Path, pathlib.Path]:
    """Write the rig's URDF and controllers into ``folder``; return both paths."""
    urdf = folder / 'sensor_rig.urdf'
    urdf.write_text(sensor_rig_urdf(), encoding='utf-8')
    controllers = folder / 'sensor_rig.yaml'
    controllers.write_text(CONTROLLERS_YAML, encoding='utf-8')
    return urdf, controllers
