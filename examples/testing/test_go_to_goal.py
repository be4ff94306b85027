"""The go-to-goal node against the shipped rover in the room world, in sim time."""

import math

import pytest
from geometry_msgs.msg import PoseStamped
from go_to_goal import STOP_DISTANCE, GoToGoal

ROVER = 'package://pan_tilt_sim/urdf/diff_drive_rover.urdf'
ROOM = 'package://pan_tilt_sim/config/worlds/room.yaml'
WALL_EAST_X = 2.0  # the inner face of the room's east wall (m)
LIDAR_X = 0.1  # the lidar sits this far ahead of base_link (m)


def goal(x: float, y: float) -> PoseStamped:
    message = PoseStamped()
    message.header.frame_id = 'odom'
    message.pose.position.x, message.pose.position.y = x, y
    return message


def distance_to(pose, x: float, y: float) -> float:
    return math.hypot(pose.position.x - x, pose.position.y - y)


@pytest.fixture
def rover(sim):
    return sim(robot=ROVER, world=ROOM)


def test_it_arrives_within_5_cm(rover):
    node = rover.add_node(GoToGoal())
    rover.publish('goal_pose', goal(1.2, -0.3))
    rover.run_until(lambda: node.arrived, timeout=20.0)
    assert distance_to(rover.entity_pose('diff_drive_rover'), 1.2, -0.3) < 0.05


def test_it_stops_at_the_wall_it_sees(rover):
    node = rover.add_node(GoToGoal())
    rover.publish('goal_pose', goal(3.0, 0.0))  # beyond the east wall
    rover.run_until(lambda: node.blocked, timeout=20.0)
    rover.step(1.0)  # and stays stopped
    x = rover.entity_pose('diff_drive_rover').position.x
    assert node.blocked
    assert WALL_EAST_X - LIDAR_X - STOP_DISTANCE - 0.15 < x < WALL_EAST_X - LIDAR_X - 0.2


def test_it_recovers_from_a_reset(rover):
    node = rover.add_node(GoToGoal())
    rover.publish('goal_pose', goal(1.2, -0.3))
    rover.step(2.0)
    assert distance_to(rover.entity_pose('diff_drive_rover'), 0.0, 0.0) > 0.2
    rover.reset()  # the robot is back at the origin, its odometry too
    rover.run_until(lambda: node.arrived, timeout=20.0)
    assert distance_to(rover.entity_pose('diff_drive_rover'), 1.2, -0.3) < 0.05
