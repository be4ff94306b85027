"""sim_node: the seeds' Gazebo + gazebo_ros_control, as one headless rclpy node.

Thin ROS glue around :class:`~pan_tilt_sim.sim.engine.Simulation`: parameters
in, command topics in, JointState and /clock out.  A wall timer ticks every
``TICK_PERIOD_S`` and runs, per tick, the physics steps that wall time asks
for (see :mod:`pan_tilt_sim.ros.pacing`); subscription callbacks only store the
latest command, and only the tick writes to the simulation.
"""

from __future__ import annotations

import dataclasses
import math

from rcl_interfaces.msg import SetParametersResult
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from pan_tilt_sim.controllers import CommandController, CommandResult
from pan_tilt_sim.controllers.joint_state_controller import JointStateController
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.ros import parameters, services
from pan_tilt_sim.ros.features import NodeFeatures
from pan_tilt_sim.ros.gain_parameters import GainParameters
from pan_tilt_sim.ros.pacing import Pacer
from pan_tilt_sim.ros.ros_interfaces import (
    COMMAND_MESSAGES,
    NANOSECONDS_PER_SECOND,
    clock_message,
    joint_state_message,
)
from pan_tilt_sim.sim.engine import Simulation

NODE_NAME = 'sim_node'
# Wall seconds between ticks when paced to real time: one JointState (50 Hz)
# per tick, and each wake-up of rclpy's executor (~0.35 ms) costs < 2 % CPU.
TICK_PERIOD_S = 0.02
CLOCK_PERIOD_S = 0.01  # sim seconds between /clock messages (100 Hz of sim time)
QUEUE_DEPTH = 10
WARNING_THROTTLE_S = 1.0
_OWN_PARAMETERS = {field.name for field in dataclasses.fields(parameters.SimParameters)}
PAUSED = 'paused'  # the parameter; services and set_paused() go through it


def clock_period_steps(time_step: float) -> int:
    """Return the physics steps between /clock messages: the whole number nearest 10 ms.

    /clock stamps stay on the step grid, so with a time step that does not
    divide 10 ms the period is the nearest whole number of steps (halves
    round up): 9 ms at 0.003 s, 12 ms at 0.004 s, every step from 0.02 s on.
    """
    return max(1, math.floor(CLOCK_PERIOD_S / time_step + 0.5 + 1e-9))


class SimNode(Node):
    """Loads the robot and its controllers, and runs them in PyBullet."""

    def __init__(self, **kwargs) -> None:
        super().__init__(NODE_NAME, **kwargs)
        self.settings = parameters.declare_parameters(self)
        description = load_description(
            self.settings.robot_description_file, self.settings.xacro_args)
        controllers = load_controllers_config(self.settings.controllers_file)
        self.robot_namespace = naming.resolve_robot_namespace(
            self.get_namespace(), self.settings.robot_namespace,
            controllers.namespace, description.plugin_namespace)
        self.simulation = Simulation(
            description, controllers, self.settings.time_step, gui=self.settings.gui,
            initial_positions=self.settings.initial_positions, logger=self.get_logger())
        self._paused = self.settings.paused
        # Commands taken per controller (ignored ones included): a cheap health figure.
        self.commands_received = {c.name: 0 for c in self.simulation.command_controllers()}
        self._pacer = Pacer(self.settings.real_time_factor, self.settings.time_step)
        self._clock_every = clock_period_steps(self.settings.time_step)
        self._clock_publisher = self.create_publisher(Clock, '/clock', QUEUE_DEPTH)
        self._clock_message = Clock()
        self._wire_controllers()
        try:
            self.gain_parameters = GainParameters(self, self.simulation.controllers)
            self.features = NodeFeatures(
                self, self.simulation, self.robot_namespace, gui=self.settings.gui)
        except BaseException:
            self.simulation.close()
            raise
        self._publish_clock()
        self.features.after_steps()  # their first samples at t = 0, as /clock's
        self._timer = self.create_timer(self._tick_period(), self._on_tick)
        # Checked in the on-set callback, applied in the post-set one: a change
        # that any callback refuses is applied nowhere.
        self.add_on_set_parameters_callback(self._check_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._world_services = services.create_world_services(
            self, reset=self.reset, set_paused=self.set_paused)
        # Actuators, start positions, PyBullet's load messages, unstable gains.
        self.simulation.report_startup()
        clock_period = self._clock_every * self.settings.time_step
        if abs(clock_period - CLOCK_PERIOD_S) > 1e-9:
            self.get_logger().info(
                f'/clock every {self._clock_every} steps ({clock_period * 1e3:g} ms of sim '
                f'time): the nearest whole number of time_step to 10 ms')
        self.get_logger().info(
            f"simulating '{description.name}' from {description.source} "
            f"with {len(self.simulation.controllers)} controllers; topics under "
            f"'{self.robot_namespace or '/'}', time_step {self.settings.time_step} s, "
            f'real_time_factor {self._pacer.real_time_factor}')

    def create_publisher(self, *args, **kwargs):
        """Create a publisher without rclpy's default QoS-event handler (see below)."""
        kwargs.setdefault('event_callbacks', PublisherEventCallbacks(use_default_callbacks=False))
        return super().create_publisher(*args, **kwargs)

    def create_subscription(self, *args, **kwargs):
        """Create a subscription without rclpy's default QoS-event handler.

        Each default handler is one more waitable that rclpy's executor walks
        in Python at every wake-up; dropping them cut sim_node's CPU at
        real_time_factor 1 from ~3.9 % to ~3.2 % of a core.  A peer with
        incompatible QoS is still warned about on the peer's side.
        """
        kwargs.setdefault('event_callbacks',
                          SubscriptionEventCallbacks(use_default_callbacks=False))
        return super().create_subscription(*args, **kwargs)

    def topic(self, *names: str) -> str:
        """Absolute name of a topic of the robot."""
        return naming.join(self.robot_namespace, *names)

    def run_steps(self, steps: int) -> None:
        """Advance ``steps`` physics steps, publishing /clock and the features when due."""
        simulation = self.simulation
        while steps > 0:
            chunk = min(steps, self._clock_every - simulation.steps % self._clock_every)
            simulation.advance(chunk)
            steps -= chunk
            if simulation.steps % self._clock_every == 0:
                self._publish_clock()
            # Every /clock period, not once per batch: batches at factor 0 last
            # ~5 ms of wall time, which may be many frames of sim time.
            self.features.after_steps()

    @property
    def paused(self) -> bool:
        """Whether the physics is held."""
        return self._paused

    @property
    def real_time_factor(self) -> float:
        """The pace the physics runs at now: sim seconds per wall second (0: flat out)."""
        return self._pacer.real_time_factor

    def set_paused(self, paused: bool) -> None:
        """Hold or release the physics (topics stay alive); the ``paused`` parameter follows."""
        result, = self.set_parameters([Parameter(PAUSED, value=paused)])
        if not result.successful:
            self.get_logger().error(f"cannot set '{PAUSED}': {result.reason}")

    def _apply_paused(self, paused: bool) -> None:
        if paused != self._paused:
            self._paused = paused
            self._pacer.restart()
            self._retime()

    def reset(self, *, reset_time: bool = True) -> None:
        """Put the robot back to its initial state; sim time to 0 if asked (/clock says so).

        Every periodic publication (joint states, TF, camera) starts again from now.
        """
        self.simulation.reset(reset_time=reset_time)
        self._pacer.restart()
        self._publish_clock()
        self.features.reset()
        self.features.after_steps()

    def destroy_node(self) -> None:
        """Stop ticking and release PyBullet."""
        self._timer.cancel()
        self.simulation.close()
        logger = self.get_logger()
        super().destroy_node()
        # Once the node is gone: its rosout publisher may share a dead context.
        logger.debug('PyBullet disconnected, node destroyed')

    def _tick_period(self) -> float:
        # Paused, a zero-period timer would spin the CPU for nothing.
        return 0.0 if self._pacer.fast and not self._paused else TICK_PERIOD_S

    def _retime(self) -> None:
        """Give the tick timer the period that the pace and the pause state call for."""
        period_ns = round(self._tick_period() * NANOSECONDS_PER_SECOND)
        if self._timer.timer_period_ns != period_ns:
            self._timer.timer_period_ns = period_ns
            self._timer.reset()

    def _on_tick(self) -> None:
        if self._paused:
            return
        steps = self._pacer.steps_due()
        if steps:
            self.run_steps(steps)

    def _publish_clock(self) -> None:
        self._clock_publisher.publish(
            clock_message(self.simulation.time, self._clock_message))

    def _wire_controllers(self) -> None:
        for controller in self.simulation.controllers:
            if isinstance(controller, JointStateController):
                publisher = self.create_publisher(
                    JointState, self.topic('joint_states'), QUEUE_DEPTH)
                controller.set_sink(self._joint_state_sink(publisher))
            elif isinstance(controller, CommandController):
                message_type, extract = COMMAND_MESSAGES[controller.command_kind]
                self.create_subscription(
                    message_type, self.topic(controller.name, controller.command_topic),
                    self._command_callback(controller, extract), QUEUE_DEPTH)

    def _joint_state_sink(self, publisher):
        message = JointState()

        def publish(time, names, positions, velocities, efforts) -> None:
            publisher.publish(
                joint_state_message(time, names, positions, velocities, efforts, message))
        return publish

    def _command_callback(self, controller: CommandController, extract):
        logger = self.get_logger()
        name = controller.name

        def store(message) -> None:
            self.commands_received[name] += 1
            value = extract(message)
            result = controller.set_command(value)
            if result is not CommandResult.ACCEPTED:
                logger.warning(f'{controller.name}: {controller.command_problem(value, result)}',
                               throttle_duration_sec=WARNING_THROTTLE_S)
        return store

    @staticmethod
    def _own_updates(changed: list[Parameter]) -> dict:
        """Return the node's own parameters among ``changed``, coerced and checked."""
        updates = {p.name: parameters.runtime_value(p) for p in changed
                   if p.name in _OWN_PARAMETERS}  # other callbacks own the rest
        if 'real_time_factor' in updates:
            parameters.check_real_time_factor(updates['real_time_factor'])
        return updates

    def _check_parameters(self, changed: list[Parameter]) -> SetParametersResult:
        try:
            self._own_updates(changed)
        except ConfigurationError as err:
            return SetParametersResult(successful=False, reason=str(err))
        return SetParametersResult(successful=True)

    def _apply_parameters(self, changed: list[Parameter]) -> None:
        updates = self._own_updates(changed)  # accepted by _check_parameters
        if PAUSED in updates:
            self._apply_paused(updates[PAUSED])
        if 'real_time_factor' in updates:
            self._pacer.real_time_factor = updates['real_time_factor']
            self._retime()
