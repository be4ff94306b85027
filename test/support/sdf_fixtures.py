"""SDF robots and worlds for the tests, written here (no file of any Gazebo package).

:func:`rover_sdf` is a small differential-drive robot as gz-sim users write
them: a chassis box, two revolute wheels whose joints sit where the wheels
turn, a ball-jointed caster behind them that carries part of the weight, a
gpu_lidar on a mast, an IMU, gz-sim's DiffDrive and JointStatePublisher
systems.  :func:`cylinders_world` is an
SDF world with a ground plane and static cylinders.
"""

from __future__ import annotations

import pathlib
from collections.abc import Sequence

WHEEL_RADIUS = 0.05  # m
WHEEL_SEPARATION = 0.3  # m, between the wheels' centres
CHASSIS = (0.4, 0.25, 0.1)  # m: the chassis box
CHASSIS_HEIGHT = 0.08  # m: the chassis centre above the base frame
LIDAR_HEIGHT = 0.2  # m: the lidar's beam plane above the model frame
LIDAR_SAMPLES = 360
LIDAR_RANGE = (0.12, 10.0)  # m
CASTER_RADIUS = 0.025  # m
CASTER_X = -0.15  # m


def rover_sdf(*, version: str = '1.9', name: str = 'sdf_rover', lidar_noise: float = 0.0,
              extra: str = '', lidar_topic: str = 'scan') -> str:
    """Return the SDF of the rover (its base link's frame on the ground, x forward)."""
    cx, cy, cz = CHASSIS
    wheel_z = WHEEL_RADIUS
    noise = (f'<noise><type>gaussian</type><mean>0</mean><stddev>{lidar_noise}</stddev>'
             '</noise>' if lidar_noise else '')

    def wheel(side: str, y: float) -> str:
        # The link frame is the model's; the joint sits at the wheel's centre (relative to
        # the child link by default), its axis the joint frame's z turned onto +y.
        return f'''
    <link name="{side}_wheel">
      <inertial><pose>0 {y} {wheel_z} -1.5707963267948966 0 0</pose><mass>0.5</mass>
        <inertia><ixx>0.0004</ixx><iyy>0.0004</iyy><izz>0.000625</izz></inertia></inertial>
      <collision name="tyre">
        <pose>0 {y} {wheel_z} -1.5707963267948966 0 0</pose>
        <geometry><cylinder><radius>{WHEEL_RADIUS}</radius><length>0.04</length></cylinder>
        </geometry>
        <surface><friction><ode><mu>1.0</mu><mu2>1.0</mu2></ode></friction></surface>
      </collision>
      <visual name="tyre">
        <pose>0 {y} {wheel_z} -1.5707963267948966 0 0</pose>
        <geometry><cylinder><radius>{WHEEL_RADIUS}</radius><length>0.04</length></cylinder>
        </geometry>
        <material><diffuse>0.1 0.1 0.1 1</diffuse></material>
      </visual>
    </link>
    <joint name="{side}_wheel_joint" type="revolute">
      <parent>chassis</parent><child>{side}_wheel</child>
      <pose>0 {y} {wheel_z} -1.5707963267948966 0 0</pose>
      <axis><xyz>0 0 1</xyz></axis>
    </joint>'''

    return f'''<?xml version="1.0"?>
<!-- a small rover, as gz-sim users write them -->
<sdf version="{version}">
  <model name="{name}">
    <link name="chassis">
      <pose>0 0 0 0 0 0</pose>
      <inertial><pose>{CASTER_X / 3} 0 {CHASSIS_HEIGHT} 0 0 0</pose><mass>4.0</mass>
        <inertia><ixx>0.03</ixx><iyy>0.06</iyy><izz>0.07</izz></inertia></inertial>
      <collision name="body">
        <pose>0 0 {CHASSIS_HEIGHT} 0 0 0</pose>
        <geometry><box><size>{cx} {cy} {cz}</size></box></geometry>
      </collision>
      <visual name="body">
        <pose>0 0 {CHASSIS_HEIGHT} 0 0 0</pose>
        <geometry><box><size>{cx} {cy} {cz}</size></box></geometry>
        <material><script><uri>file://media/materials/scripts/gazebo.material</uri>
          <name>Gazebo/Orange</name></script></material>
      </visual>
      <sensor name="imu" type="imu">
        <update_rate>100</update_rate><topic>imu</topic>
        <gz_frame_id>chassis</gz_frame_id>
      </sensor>
    </link>
    <link name="lidar">
      <pose relative_to="chassis">0 0 {LIDAR_HEIGHT - 0.02} 0 0 0</pose>
      <inertial><mass>0.1</mass>
        <inertia><ixx>1e-4</ixx><iyy>1e-4</iyy><izz>1e-4</izz></inertia></inertial>
      <visual name="head">
        <geometry><cylinder><radius>0.03</radius><length>0.04</length></cylinder></geometry>
      </visual>
      <sensor name="lidar" type="gpu_lidar">
        <pose>0 0 0.02 0 0 0</pose>
        <update_rate>10</update_rate>
        <topic>{lidar_topic}</topic>
        <gz_frame_id>lidar</gz_frame_id>
        <lidar>
          <scan><horizontal><samples>{LIDAR_SAMPLES}</samples><resolution>1</resolution>
            <min_angle>-3.14159</min_angle><max_angle>3.14159</max_angle></horizontal></scan>
          <range><min>{LIDAR_RANGE[0]}</min><max>{LIDAR_RANGE[1]}</max>
            <resolution>0.01</resolution></range>
          {noise}
        </lidar>
      </sensor>
    </link>
    <joint name="lidar_joint" type="fixed">
      <parent>chassis</parent><child>lidar</child>
    </joint>
    {wheel('left', WHEEL_SEPARATION / 2)}
    {wheel('right', -WHEEL_SEPARATION / 2)}
    <link name="caster">
      <pose>{CASTER_X} 0 {CASTER_RADIUS} 0 0 0</pose>
      <inertial><mass>0.05</mass>
        <inertia><ixx>1e-5</ixx><iyy>1e-5</iyy><izz>1e-5</izz></inertia></inertial>
      <collision name="ball">
        <geometry><sphere><radius>{CASTER_RADIUS}</radius></sphere></geometry>
        <surface><friction><ode><mu>0.1</mu><mu2>0.1</mu2></ode></friction></surface>
      </collision>
    </link>
    <joint name="caster_joint" type="ball">
      <parent>chassis</parent><child>caster</child>
    </joint>
    <plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">
      <left_joint>left_wheel_joint</left_joint>
      <right_joint>right_wheel_joint</right_joint>
      <wheel_separation>{WHEEL_SEPARATION}</wheel_separation>
      <wheel_radius>{WHEEL_RADIUS}</wheel_radius>
      <topic>cmd_vel</topic>
      <odom_topic>odom</odom_topic>
      <tf_topic>tf</tf_topic>
      <frame_id>odom</frame_id>
      <child_frame_id>chassis</child_frame_id>
      <odom_publish_frequency>50</odom_publish_frequency>
    </plugin>
    <plugin filename="gz-sim-joint-state-publisher-system"
            name="gz::sim::systems::JointStatePublisher">
      <topic>joint_states</topic>
    </plugin>
    {extra}
  </model>
</sdf>
'''


def cylinders_world(cylinders: Sequence[tuple[float, float, float]], *, ground: bool = True,
                    step: float | None = None, extra: str = '', version: str = '1.9') -> str:
    """Return an SDF world: a ground plane and static cylinders (x, y, radius), 1 m tall."""
    parts = []
    if ground:
        parts.append('''
    <model name="ground_plane"><static>true</static>
      <link name="link">
        <collision name="collision"><geometry><plane><normal>0 0 1</normal>
          <size>100 100</size></plane></geometry></collision>
        <visual name="visual"><geometry><plane><normal>0 0 1</normal><size>100 100</size>
          </plane></geometry></visual>
      </link>
    </model>''')
    for index, (x, y, radius) in enumerate(cylinders):
        parts.append(f'''
    <model name="pillar_{index}"><static>true</static>
      <pose>{x} {y} 0.5 0 0 0</pose>
      <link name="link">
        <collision name="c"><geometry><cylinder><radius>{radius}</radius><length>1</length>
          </cylinder></geometry></collision>
        <visual name="v"><geometry><cylinder><radius>{radius}</radius><length>1</length>
          </cylinder></geometry></visual>
      </link>
    </model>''')
    physics = (f'<physics name="fast" type="ode"><max_step_size>{step}</max_step_size>'
               '<real_time_factor>1</real_time_factor></physics>' if step else '')
    return f'''<?xml version="1.0"?>
<sdf version="{version}">
  <world name="pillars">
    <plugin filename="gz-sim-physics-system" name="gz::sim::systems::Physics"/>
    <plugin filename="gz-sim-sensors-system" name="gz::sim::systems::Sensors">
      <render_engine>ogre2</render_engine></plugin>
    <light name="sun" type="directional"><direction>-0.5 0.1 -0.9</direction></light>
    <scene><shadows>0</shadows></scene>
    {physics}
    {''.join(parts)}
    {extra}
  </world>
</sdf>
'''


def write(path: pathlib.Path, text: str) -> pathlib.Path:
    """Write ``text`` to ``path`` (folders made); return the path."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding='utf-8')
    return path


def model_folder(root: pathlib.Path, name: str, sdf: str, *,
                 versions: Sequence[tuple[str, str]] = (('1.9', 'model.sdf'),)) -> pathlib.Path:
    """Write a Gazebo model folder ``root/name`` whose model.config lists ``versions``.

    Each ``(version, file)`` file gets ``sdf`` with its model named
    ``name`` plus the file's stem, so a test sees which one was read.
    """
    folder = root / name
    entries = ''.join(f'<sdf version="{version}">{file}</sdf>' for version, file in versions)
    write(folder / 'model.config', f'<?xml version="1.0"?><model><name>{name}</name>'
                                   f'<version>1.0</version>{entries}</model>')
    for _version, file in versions:
        write(folder / file, sdf.replace('MODEL_NAME', f'{name}_{pathlib.Path(file).stem}'))
    return folder


def box_model_sdf(*, static: bool = True, size: float = 0.5, version: str = '1.9',
                  extra_link: str = '') -> str:
    """Return an SDF file of one box model (named MODEL_NAME, see :func:`model_folder`)."""
    return f'''<?xml version="1.0"?>
<sdf version="{version}">
  <model name="MODEL_NAME"><static>{str(static).lower()}</static>
    <link name="box">
      <pose>0 0 {size / 2} 0 0 0</pose>
      <collision name="c"><geometry><box><size>{size} {size} {size}</size></box></geometry>
      </collision>
      <visual name="v"><geometry><box><size>{size} {size} {size}</size></box></geometry>
      </visual>
    </link>
    {extra_link}
  </model>
</sdf>
'''
