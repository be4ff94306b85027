"""A real grasp: gripper action controllers closing on a spawned box, in PyBullet.

The small arm of gripper_fixtures.py (a lift carrying two fingers, the right
one a mimic of the left) and a 0.2 kg, 4 cm box between the fingers.  The
fingers' ``<mu1>``/``<mu2>`` (2.0) against the box's PyBullet default (0.5)
give a friction coefficient of 1.0, so a grip of F newtons holds up to F
newtons of weight: 6 N holds the 1.96 N box, 1 N does not.  Goals are run
in-process through the controller, as the node's action server runs them.
"""

import math

import pytest
from gripper_fixtures import (
    BOX_SIZE,
    FINGER_EFFORT_LIMIT,
    FINGER_JOINT,
    FINGER_MU,
    FINGER_OPEN,
    LIFT_JOINT,
    MIMIC_JOINT,
    grasp_box_urdf,
    write_gripper_arm,
)

from pan_tilt_sim.controllers.grippers.gripper_action_controller import GripperRequest
from pan_tilt_sim.controllers.trajectory.trajectory_goal import GoalStatus
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.entities import Entities

TIME_STEP = 0.001
POSITION_TYPE = 'position_controllers/GripperActionController'
EFFORT_TYPE = 'effort_controllers/GripperActionController'
PARALLEL_TYPE = 'parallel_gripper_action_controller/GripperActionController'
GRIP = 6.0  # N: holds the box (1.96 N of weight) with friction 1.0
WEAK_GRIP = 1.0  # N: does not
HALF_BOX = BOX_SIZE / 2
LIFT = 0.15  # m
DYNAMICS_LATERAL_FRICTION = 1  # index in pybullet.getDynamicsInfo


class Rig:
    """The arm in a simulation with a ground, and a box spawned on demand."""

    def __init__(self, folder, gripper_type=POSITION_TYPE, *, finger_mu=True, **gripper):
        urdf, controllers = write_gripper_arm(folder, gripper_type, finger_mu=finger_mu,
                                              **gripper)
        self.sim = make_simulation(urdf, controllers, TIME_STEP)
        self.entities = Entities(self.sim.physics, self.sim.description.name)
        self.gripper = self.sim.controller('gripper_controller')

    def close(self) -> None:
        self.entities.close()
        self.sim.close()

    def run(self, seconds: float) -> None:
        self.sim.advance(round(seconds / TIME_STEP))

    def run_goal(self, request: GripperRequest, budget_s: float = 5.0):
        """Run a goal until it ends (within ``budget_s`` of sim time); return it."""
        goal = self.gripper.start_goal(request, self.sim.time)
        for _ in range(round(budget_s / 0.01)):
            if goal.done:
                break
            self.run(0.01)
        assert goal.done, f'the goal did not end within {budget_s} s'
        return goal

    def finger(self) -> float:
        return self.sim.joint_positions()[FINGER_JOINT]

    def spawn_box(self, **box) -> None:
        self.entities.spawn('box', resource_string=grasp_box_urdf(**box),
                            pose=Transform((0.0, 0.0, HALF_BOX)))

    def box(self) -> tuple[float, float, float]:
        return self.entities.state('box').pose.translation

    def grasp(self, max_effort: float, **box):
        """Open, spawn the box between the fingers, close on it; return the closing goal."""
        opened = self.run_goal(GripperRequest(FINGER_OPEN, max_effort))
        assert opened.status is GoalStatus.SUCCEEDED
        self.spawn_box(**box)
        self.run(0.1)
        return self.run_goal(GripperRequest(0.0, max_effort))

    def lift(self, height: float = LIFT, seconds: float = 1.5) -> None:
        self.sim.controller('lift_controller').set_command(height)
        self.run(seconds)


@pytest.fixture
def rig(tmp_path):
    made = []

    def make(gripper_type=POSITION_TYPE, **options):
        made.append(Rig(tmp_path, gripper_type, **options))
        return made[-1]

    yield make
    for each in made:
        each.close()


def test_the_gripper_reaches_an_open_position_within_its_tolerance_the_mimic_finger_follows(rig):
    arm = rig()
    goal = arm.run_goal(GripperRequest(0.04, 0.0))
    assert goal.status is GoalStatus.SUCCEEDED
    assert goal.result.reached_goal and not goal.result.stalled
    assert abs(goal.result.position - 0.04) < 0.01
    arm.run(0.5)  # still driven there after the goal
    positions = arm.sim.joint_positions()
    assert positions[FINGER_JOINT] == pytest.approx(0.04, abs=1e-4)
    assert positions[MIMIC_JOINT] == pytest.approx(positions[FINGER_JOINT], abs=1e-3)


@pytest.mark.parametrize(('allow_stalling', 'status'), [(True, GoalStatus.SUCCEEDED),
                                                       (False, GoalStatus.ABORTED)])
def test_closing_on_a_box_stalls_with_the_box_between_the_fingers(rig, allow_stalling, status):
    arm = rig(allow_stalling=allow_stalling, stall_timeout=0.5)
    goal = arm.grasp(GRIP)
    assert goal.status is status
    assert goal.result.stalled and not goal.result.reached_goal
    assert goal.result.position == pytest.approx(HALF_BOX, abs=1e-3)
    assert goal.result.effort == GRIP  # the position type reports the max_effort in force
    positions = arm.sim.joint_positions()
    assert positions[MIMIC_JOINT] == pytest.approx(HALF_BOX, abs=1e-3)
    x, y, z = arm.box()
    assert (x, y, z) == pytest.approx((0.0, 0.0, HALF_BOX), abs=2e-3)


def test_max_effort_is_the_force_on_the_fingers(rig):
    arm = rig()
    arm.grasp(GRIP)
    arm.run(0.2)
    # The ideal actuator pushes (toward closed: -y) with exactly the force it may.
    assert arm.sim.handles[FINGER_JOINT].effort == pytest.approx(-GRIP, rel=1e-6)


def test_the_box_stays_held_through_a_lift_and_does_not_creep(rig):
    arm = rig()
    arm.grasp(GRIP)
    arm.lift()
    assert arm.sim.joint_positions()[LIFT_JOINT] == pytest.approx(LIFT, abs=1e-3)
    lifted = arm.box()[2]
    assert lifted == pytest.approx(HALF_BOX + LIFT, abs=2e-3)
    arm.run(3.0)
    assert abs(arm.box()[2] - lifted) < 1e-4
    assert arm.finger() == pytest.approx(HALF_BOX, abs=1e-3)


def test_a_grip_weaker_than_the_box_is_heavy_lets_it_slip_out(rig):
    arm = rig()
    arm.grasp(WEAK_GRIP)
    arm.lift()
    assert arm.box()[2] == pytest.approx(HALF_BOX, abs=2e-3)  # left on the ground
    assert arm.finger() == pytest.approx(0.0, abs=1e-3)  # the fingers closed on nothing


def test_without_the_fingers_friction_tags_the_same_grip_lets_the_box_slip(rig):
    arm = rig(finger_mu=False)
    arm.grasp(GRIP)
    arm.lift()
    assert arm.box()[2] == pytest.approx(HALF_BOX, abs=2e-3)


def test_the_fingers_and_the_box_get_their_mu_tags_as_pybullet_friction(rig):
    arm = rig()
    arm.spawn_box(mu=0.7)
    physics = arm.sim.physics
    finger = pybullet.getDynamicsInfo(physics.body_id, physics.link_index('left_finger'),
                                      physicsClientId=physics.client_id)
    box = pybullet.getDynamicsInfo(arm.entities.get('box').body, -1,
                                   physicsClientId=physics.client_id)
    assert finger[DYNAMICS_LATERAL_FRICTION] == FINGER_MU
    assert box[DYNAMICS_LATERAL_FRICTION] == pytest.approx(0.7)


def test_the_effort_type_grasps_and_lifts_with_its_pid_clamped_to_max_effort(rig):
    arm = rig(EFFORT_TYPE, allow_stalling=True, gains={FINGER_JOINT: {'p': 2000.0, 'd': 5.0}})
    goal = arm.grasp(GRIP)
    assert goal.status is GoalStatus.SUCCEEDED and goal.result.stalled
    assert goal.result.effort == pytest.approx(-GRIP)  # the PID's effort, clamped
    arm.lift()
    assert arm.box()[2] == pytest.approx(HALF_BOX + LIFT, abs=2e-3)


def test_the_parallel_type_grasps_with_the_effort_of_its_max_effort_interface(rig):
    arm = rig(PARALLEL_TYPE, allow_stalling=True, max_effort=GRIP,
              max_effort_interface=f'{FINGER_JOINT}/max_effort')
    request, _problem = arm.gripper.goal_request([0.0], [], [])
    opened = arm.run_goal(arm.gripper.goal_request([FINGER_OPEN], [], [])[0])
    assert opened.status is GoalStatus.SUCCEEDED
    arm.spawn_box()
    arm.run(0.1)
    goal = arm.run_goal(request)
    assert goal.status is GoalStatus.SUCCEEDED and goal.result.stalled
    assert goal.result.effort == pytest.approx(-GRIP, rel=1e-6)  # what the actuator applied
    arm.lift()
    assert arm.box()[2] == pytest.approx(HALF_BOX + LIFT, abs=2e-3)


def test_once_the_gripper_is_deactivated_its_joint_gets_its_effort_limit_back(rig):
    arm = rig()
    arm.grasp(GRIP)
    handle = arm.sim.handles[FINGER_JOINT]
    assert handle.force_limit == GRIP
    arm.sim.manager.switch(deactivate=['gripper_controller'])
    assert handle.force_limit == FINGER_EFFORT_LIMIT
    assert not math.isnan(arm.finger())


def test_a_max_effort_interface_the_urdf_block_lacks_stops_start_up_naming_it(tmp_path):
    urdf, controllers = write_gripper_arm(
        tmp_path, PARALLEL_TYPE, max_velocity_interface=f'{FINGER_JOINT}/max_velocity')
    with pytest.raises(ConfigurationError, match=r"'max_velocity' command interface of joint "
                                                 f"'{FINGER_JOINT}'"):
        make_simulation(urdf, controllers, TIME_STEP)
