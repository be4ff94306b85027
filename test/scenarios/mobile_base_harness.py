"""One harness for the mobile bases on sim_node, driven closed loop from the probe.

A base (the rover, the mecanum and omni bases, the steered cars, the tricycle) runs
in-process, paused, at real_time_factor 0 on the ground; a test commands it, steps the
physics one controller update (:meth:`MobileBase.update`) and reads the odometry that update
published, so the loop's delay is one update whatever the machine's load.  The true pose
comes from simulation_interfaces' GetEntityState.  :class:`BaseKind` says what differs
between the bases: the entity, the controller and its topics, the update period.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import pathlib
import time
from collections.abc import Callable, Iterator

import pytest
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from node_harness import PROBE_QUEUE, sim_node
from rcl_interfaces.msg import Log
from sim_interfaces_client import SimInterfaces, position
from tf2_msgs.msg import TFMessage

from pan_tilt_sim.ros.controller_bindings import WARNING_THROTTLE_S

TIME_STEP = 0.001  # s
FLOOD_COUNT = 50  # non-finite commands in a burst


@dataclasses.dataclass(frozen=True)
class BaseKind:
    """What one kind of mobile base is on sim_node: its entity, controller and topics."""

    robot: str  # the entity's name (GetEntityState)
    controller: str  # the controller that takes the twist
    odometry: str  # the odometry topic
    update_steps: int  # physics steps per controller update (one odometry message)
    holonomic: bool = False  # command(vx, vy, wz) instead of command(vx, wz)
    tf: str | None = None  # the odometry TF topic the harness collects
    wait_for_tf: bool = False  # also wait until sim_node sees the probe's TF subscriber
    state: tuple[type, str] | None = None  # the controller state message and its topic
    log: bool = False  # collect /rosout


class MobileBase:
    """A mobile base on sim_node, driven from the probe one controller update at a time."""

    def __init__(self, sim, kind: BaseKind) -> None:
        self.sim = sim
        self.node = sim.node
        self.kind = kind
        self.odometry: list[Odometry] = sim.collect(Odometry, kind.odometry)
        if kind.tf is not None:
            self.tf: list[TFMessage] = sim.collect(TFMessage, kind.tf)
        if kind.state is not None:
            self.states: list = sim.collect(*kind.state)
        if kind.log:
            self.log: list[Log] = sim.collect(Log, '/rosout', PROBE_QUEUE)
        self.interfaces = SimInterfaces(sim)
        sim.wait_for_subscribers(kind.odometry)
        if kind.wait_for_tf:
            sim.wait_for_subscribers(kind.tf)

    def command(self, *velocity: float) -> None:
        """Publish an unstamped twist, (vx, wz) or holonomic (vx, vy, wz); return once taken."""
        message = TwistStamped()
        twist = message.twist
        if self.kind.holonomic:
            twist.linear.x, twist.linear.y, twist.angular.z = velocity
        else:
            twist.linear.x, twist.angular.z = velocity
        self.sim.command(self.kind.controller, message)

    def update(self) -> Odometry:
        """Step one controller update; return the odometry it published."""
        count = len(self.odometry)
        self.node.step(self.kind.update_steps)
        assert self.sim.spin_until(lambda: len(self.odometry) > count), 'no odometry came'
        return self.odometry[-1]

    def true_pose(self) -> tuple[tuple[float, float, float], float, float]:
        """Return the base's true position, heading and forward speed (GetEntityState)."""
        state = self.interfaces.entity_state(self.kind.robot)
        q = state.pose.orientation
        return position(state), 2.0 * math.atan2(q.z, q.w), state.twist.linear.x

    def true_speed(self) -> float:
        """Return the base's true speed over the ground (m/s; the twist is in the world frame)."""
        linear = self.interfaces.entity_state(self.kind.robot).twist.linear
        return math.hypot(linear.x, linear.y)

    def true_yaw_rate(self) -> float:
        """Return the base's true rate of turn (rad/s, GetEntityState)."""
        return self.interfaces.entity_state(self.kind.robot).twist.angular.z


def heading(odometry: Odometry) -> float:
    """Return the heading of an odometry message's pose."""
    q = odometry.pose.pose.orientation
    return 2.0 * math.atan2(q.z, q.w)


def running(kind: BaseKind, write: Callable[..., tuple[pathlib.Path, pathlib.Path]],
            parameters: Callable[..., dict], folder: pathlib.Path,
            **drive: object) -> contextlib.AbstractContextManager[MobileBase]:
    """Run the base ``write`` puts in ``folder``, its controller given ``parameters(**drive)``."""
    return base_on_sim_node(kind, *write(folder, parameters(**drive)))


def free_base_topics(base: MobileBase, rest_height: float) -> tuple[dict, dict]:
    """Check the base is free, standing at the origin ``rest_height`` m up; return its topics.

    The topics are sim_node's own (published, subscribed), each name to its type.
    """
    assert not base.node.simulation.physics.fixed_base
    where, _, _ = base.true_pose()
    assert where == pytest.approx((0.0, 0.0, rest_height), abs=1e-6)
    return base.sim.own_topics()


@contextlib.contextmanager
def base_on_sim_node(kind: BaseKind, description: pathlib.Path,
                     controllers: pathlib.Path) -> Iterator[MobileBase]:
    """Run the base that ``description`` and ``controllers`` describe on sim_node, on the ground."""
    with sim_node(paused=True, time_step=TIME_STEP, robot_description_file=str(description),
                  controllers_file=str(controllers), world='ground') as sim:
        yield MobileBase(sim, kind)


def holonomic_stops_after_the_timeout(base: MobileBase) -> None:
    """Command a holonomic base 0.2 m/s forward once (timeout 0.2 s); it drives, then stands."""
    base.command(0.2, 0.0, 0.0)
    for _ in range(10):  # 0.1 s: within the timeout
        base.update()
    assert base.odometry[-1].twist.twist.linear.x == pytest.approx(0.2, rel=0.05)
    for _ in range(60):
        base.update()
    assert base.odometry[-1].twist.twist.linear.x == pytest.approx(0.0, abs=1e-3)
    where, _, _ = base.true_pose()
    assert where[0] < 0.2 * 0.4


def ignores_non_finite_commands(base: MobileBase,
                                bad_command: Callable[[float], tuple[float, ...]]) -> None:
    """Drive a holonomic base at 0.2 m/s, then send a burst of ``bad_command(nan or inf)``.

    Check the base keeps its speed and the controller warns, throttled.
    """
    base.command(0.2, 0.0, 0.0)
    for _ in range(10):
        base.update()
    start = time.monotonic()
    for index in range(FLOOD_COUNT):
        base.command(*bad_command((math.nan, math.inf, -math.inf)[index % 3]))
    elapsed = time.monotonic() - start
    for _ in range(10):
        base.update()
    base.sim.drain()
    assert base.odometry[-1].twist.twist.linear.x == pytest.approx(0.2, rel=0.05)
    warnings = [entry for entry in base.log if entry.level == Log.WARN
                and base.kind.controller in entry.msg and 'not finite numbers' in entry.msg]
    assert warnings, 'no warning at all'
    assert len(warnings) <= 1 + int(elapsed / WARNING_THROTTLE_S)
