"""A ROS 1 (gazebo_ros_control) diff drive YAML on sim_node: Twist in, odom out, as noetic.

The rover of test/support/mobile_fixtures.py without ``<ros2_control>``: wheels
with ROS 1 transmissions and a gazebo_ros_control plugin, its controllers in
a ROS 1 layout YAML (``left_wheel``/``right_wheel``, no ``wheel_radius``:
noetic reads it from the wheel's collision cylinder).  In-process, paused;
the probe drives it closed loop on ``/base_controller/cmd_vel``
(unstamped) and reads ``/base_controller/odom``.
"""

from __future__ import annotations

import pytest
from geometry_msgs.msg import Twist
from mobile_fixtures import WHEEL_SEPARATION, rover_urdf
from nav_msgs.msg import Odometry
from node_harness import sim_node
from sim_interfaces_client import SimInterfaces, position

TIME_STEP = 0.001
PERIOD_STEPS = 10  # one odometry message at publish_rate 100
RECOMMAND_PERIODS = 20  # 0.2 s: well inside noetic's cmd_vel_timeout of 0.5 s
MAX_PERIODS = 1000
ROBOT = 'rover'

TRANSMISSIONS = ''.join(f'''
  <transmission name="{side}_wheel_trans">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="{side}_wheel_joint">
      <hardwareInterface>hardware_interface/VelocityJointInterface</hardwareInterface>
    </joint>
    <actuator name="{side}_wheel_motor"><mechanicalReduction>1</mechanicalReduction></actuator>
  </transmission>''' for side in ('left', 'right')) + '''
  <gazebo>
    <plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so">
      <robotNamespace>/</robotNamespace>
    </plugin>
  </gazebo>'''

ROS1_YAML = f'''\
joint_state_controller:
  type: joint_state_controller/JointStateController
  publish_rate: 50
base_controller:
  type: diff_drive_controller/DiffDriveController
  publish_rate: 100
  left_wheel: left_wheel_joint
  right_wheel: [right_wheel_joint]
  wheel_separation: {WHEEL_SEPARATION}
  pose_covariance_diagonal: [0.001, 0.001, 0.001, 0.001, 0.001, 0.03]
  twist_covariance_diagonal: [0.001, 0.001, 0.001, 0.001, 0.001, 0.03]
  base_frame_id: base_link
  linear:
    x:
      has_velocity_limits: true
      max_velocity: 0.5
      has_acceleration_limits: true
      max_acceleration: 1.0
  angular:
    z:
      has_velocity_limits: true
      max_velocity: 2.0
'''


@pytest.fixture
def ros1_rover(tmp_path):
    description = tmp_path / 'rover.urdf'
    description.write_text(rover_urdf(ROBOT, ros2_control=False, extra=TRANSMISSIONS),
                           encoding='utf-8')
    controllers = tmp_path / 'controllers.yaml'
    controllers.write_text(ROS1_YAML, encoding='utf-8')
    with sim_node(paused=True, time_step=TIME_STEP, robot_description_file=str(description),
                  controllers_file=str(controllers)) as sim:
        yield sim


def test_a_ros1_diff_drive_yaml_takes_a_twist_and_its_odometry_follows_the_true_pose(
        ros1_rover):
    sim = ros1_rover
    published, subscribed = sim.own_topics()
    assert subscribed['/base_controller/cmd_vel'] == 'geometry_msgs/msg/Twist'
    assert published['/base_controller/odom'] == 'nav_msgs/msg/Odometry'
    odometry = sim.collect(Odometry, '/base_controller/odom')
    sim.wait_for_subscribers('/base_controller/odom')
    twist = sim.probe.create_publisher(Twist, '/base_controller/cmd_vel', 10)
    assert sim.spin_until(lambda: twist.get_subscription_count() > 0)
    counts = sim.node.commands_received
    message = Twist()
    message.linear.x = 0.2

    def period() -> Odometry:
        count = len(odometry)
        sim.node.step(PERIOD_STEPS)
        assert sim.spin_until(lambda: len(odometry) > count), 'no odometry came'
        return odometry[-1]

    last = period()
    for index in range(MAX_PERIODS):
        if last.pose.pose.position.x >= 1.0:
            break
        if index % RECOMMAND_PERIODS == 0:
            before = counts['base_controller']
            twist.publish(message)
            assert sim.spin_until(lambda before=before: counts['base_controller'] > before)
        last = period()
    else:
        raise AssertionError(f'the odometry never reached 1 m: {last.pose.pose}')
    where = position(SimInterfaces(sim).entity_state(ROBOT))
    assert last.pose.pose.position.x == pytest.approx(where[0], rel=0.02)
    assert last.pose.pose.position.y == pytest.approx(where[1], abs=0.02)
    assert (last.header.frame_id, last.child_frame_id) == ('odom', 'base_link')
    assert last.pose.covariance[35] == pytest.approx(0.03)
    speeds = [message.twist.twist.linear.x for message in odometry[-5:]]
    assert speeds == pytest.approx([0.2] * 5, abs=0.02)
