"""sim_node: Gazebo + gazebo_ros_control, as one headless rclpy node.

Thin ROS glue around :class:`~pan_tilt_sim.sim.engine.Simulation`: parameters
in, command topics in, JointState and /clock out.  A wall timer ticks every
``TICK_PERIOD_S`` and runs, per tick, the physics steps that wall time asks
for (see :mod:`pan_tilt_sim.ros.pacing`); subscription callbacks only store the
latest command, and only the tick writes to the simulation.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from rcl_interfaces.msg import SetParametersResult
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock

from pan_tilt_sim.controllers.broadcasters.joint_state_broadcaster import JointStateBroadcaster
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.controller_config import ControllersConfig
from pan_tilt_sim.model.description import RobotDescription, load_description
from pan_tilt_sim.model.ros_arguments import parse_ros_arguments
from pan_tilt_sim.ros import (
    bridged_topics,
    drop_in,
    optional_interfaces,
    parameters,
    robot_spawn,
    services,
    simulation_services,
    spawned_robots,
    startup,
    topic_hardware,
    view_feed,
)
from pan_tilt_sim.ros.camera_publisher import declare_world
from pan_tilt_sim.ros.clock_publisher import CLOCK_TOPIC, ClockPublisher
from pan_tilt_sim.ros.command_reader import CommandReader
from pan_tilt_sim.ros.controller_bindings import ControllerBindings
from pan_tilt_sim.ros.features import NodeFeatures
from pan_tilt_sim.ros.gain_parameters import GainParameters
from pan_tilt_sim.ros.pacing import Pacer
from pan_tilt_sim.ros.physics_thread import PhysicsThread, Turns
from pan_tilt_sim.ros.recording import RecordedPublisher, Recorder
from pan_tilt_sim.ros.ros_interfaces import NANOSECONDS_PER_SECOND
from pan_tilt_sim.sim.engine import Simulation

NODE_NAME = 'sim_node'
# Wall seconds between ticks when paced to real time: one JointState (50 Hz)
# per tick, and few enough wake-ups that waking stays a small share of a core.
TICK_PERIOD_S = 0.02
QUEUE_DEPTH = 10
_OWN_PARAMETERS = {field.name for field in dataclasses.fields(parameters.SimParameters)}
PAUSED = 'paused'  # the parameter; services and set_paused() go through it


class SimNode(Node):
    """Loads the robot and its controllers, and runs them in PyBullet.

    The physics is driven either by a timer on the node's executor (the
    default: tests and embedding spin it on one executor with their own
    nodes) or, with ``physics_thread=True`` (the sim_node program), by a paced
    thread of its own that takes turns with the executor's callbacks through
    :attr:`turns`; spin the node on a ``TurnTakingExecutor(node.turns)``
    then (see :mod:`pan_tilt_sim.ros.physics_thread`).

    With ``robot_description_file`` empty, everything but the parameters is
    built once the ``robot_description`` topic brings the robot; named
    ``controller_manager`` it stands in for ros2_control_node, serving the
    controller_manager services itself (see :mod:`pan_tilt_sim.ros.drop_in`).
    ``ros_arguments`` are the process's command line, whose parameter files
    the controllers read there as ros2_control's controller nodes read them.
    """

    def __init__(self, *, physics_thread: bool = False, ros_arguments: Sequence[str] = (),
                 **kwargs) -> None:
        # What destroy_node releases, empty until built: a start-up error
        # destroys whatever was made before it (the rclpy node included), so an
        # in-process caller is left with no live DDS endpoints and no PyBullet.
        self.simulation: Simulation | None = None
        self.controllers: ControllerBindings | None = None
        self.features: NodeFeatures | None = None
        self.simulation_interfaces = None
        # Nodes of this process spun on sim_node's executor and destroyed with it.
        self.companion_nodes: list[Node] = []
        self._physics_thread: PhysicsThread | None = None
        self._command_reader: CommandReader | None = None
        self._timer = None
        self._description_subscription = None
        self.controller_manager: Node | None = None  # where controller_manager_msgs exists
        self.is_controller_manager = False
        # With record:=<folder>, every publisher and subscription made from then on is
        # teed into the bag (see create_publisher, create_subscription).
        self.recorder: Recorder | None = None
        self.viewer = None  # the browser view (viewer:=true), a pan_tilt_sim.ros.viewer.Viewer
        # ros_gz_bridge entries' names and types for the robot's topics (robot_from_spawn).
        self.bridged_topics: bridged_topics.BridgedTopics | None = None
        # Robots spawned after the first (robot_from_spawn), by entity name.
        self.spawned_robots: dict[str, spawned_robots.SpawnedRobot] = {}
        super().__init__(NODE_NAME, **kwargs)
        # Named controller_manager (launch's name='controller_manager'), sim_node stands
        # in for ros2_control_node: see the module pan_tilt_sim.ros.drop_in.
        self.is_controller_manager = self.get_name() == drop_in.NODE_NAME
        try:
            self._arguments = parse_ros_arguments(
                [*ros_arguments, *(kwargs.get('cli_args') or ())], 'the command line')
            self._start(physics_thread, kwargs.get('parameter_overrides') or ())
        except BaseException:
            if self.recorder is not None:  # a node that never ran leaves no bag
                self.recorder.discard()
                self.recorder = None
            self.destroy_node()
            raise

    def _start(self, physics_thread: bool, overrides: Sequence[Parameter]) -> None:
        """Read the parameters; build now from a file, or once the robot_description topic says."""
        # The world first: an SDF world's <physics> gives time_step and real_time_factor
        # their defaults (the user's parameters win), so that the parameters say what runs.
        self._world = declare_world(self)
        for line in self._world.warnings:
            self.get_logger().warning(line)
        self.settings = parameters.declare_parameters(
            self, controller_manager=self.is_controller_manager,
            world_physics=self._world.physics)
        physics_line = parameters.world_physics_line(self._world.physics, self.settings,
                                                     parameters.given_parameters(self))
        if physics_line:
            self.get_logger().info(physics_line)
        self._manager_settings = (
            drop_in.declare_manager_parameters(self, self._arguments, overrides)
            if self.is_controller_manager else None)
        # The view's address is checked first: a port in use ends start-up before anything
        # is loaded.
        self._viewer_settings = view_feed.declare_viewer(self)
        if self._viewer_settings.enabled:
            view_feed.check_viewer(self._viewer_settings)
        # With a physics thread, callbacks take turns with it (the executor needs them now).
        self.turns: Turns | None = Turns() if physics_thread else None
        if robot_spawn.declare(self):  # the world now, the robot from a spawn request
            self.bridged_topics = bridged_topics.BridgedTopics(self)
            self._robot_spawn = robot_spawn.RobotSpawnService(
                self, lambda description, spawn: self._build_spawned(
                    physics_thread, description, spawn),
                taken=(entity.name for entity in self._world.entities if entity.name),
                build_more=self._add_robot, names=lambda: self.features.entities.names(),
                is_robot=spawned_robots.is_robot,
                frame_pose=lambda frame: self.features.entities.frame_pose(frame),
                own_topics=spawned_robots.own_topics)
            return
        if self.settings.robot_description_file:
            self._build(physics_thread, load_description(
                self.settings.robot_description_file, self.settings.xacro_args))
            return
        self._description_subscription = drop_in.wait_for_description(
            self, lambda description: self._build(physics_thread, description,
                                                  from_topic=True))

    def _build_spawned(self, physics_thread: bool, description: RobotDescription,
                       spawn: robot_spawn.Spawn) -> None:
        """Build for a spawned robot: its pose and namespace as the parameters would give them."""
        self.settings = dataclasses.replace(
            self.settings, initial_pose=spawn.pose,
            robot_namespace=spawn.namespace or self.settings.robot_namespace)
        self._build(physics_thread, description, from_topic=True)
        if not self.is_controller_manager:  # Gazebo deletes any model: the world runs on
            self.features.entities.let_delete(description.name, self._remove_first_robot)

    def _add_robot(self, description: RobotDescription, spawn: robot_spawn.Spawn) -> None:
        """One more robot in the world (its plugins, sensors, controller manager), in our turn."""
        robot = spawned_robots.SpawnedRobot(
            self, self.simulation, description, namespace=spawn.namespace,
            controllers=spawned_robots.controllers_of(description), settings=self.settings,
            initial_pose=spawn.pose, world=self._world.scenery, reader=self._command_reader,
            seed=self.features.noise_seed)
        self.features.entities.add_robot(robot.name, robot.simulation.physics,
                                         remove=self._remove_robot)
        self.spawned_robots[robot.name] = robot
        for warning in description.warnings:  # what xacro said, as for the first robot
            self.get_logger().warning(warning)
        robot.simulation.report_startup()
        self.get_logger().info(
            f"simulating '{robot.name}' from {description.source} too; its topics under "
            f"'{robot.namespace or '/'}'")

    def _remove_robot(self, name: str) -> None:
        """DeleteEntity of a spawned robot: its topics, manager and body go."""
        self.spawned_robots.pop(name).destroy()

    def _remove_first_robot(self, _name: str) -> None:
        """DeleteEntity of the robot the world began with: what a spawned robot loses, it loses.

        Its topics, services, controller manager, sensors and body go; the world, its
        clock and the other robots stay (the simulation steps them without it).
        """
        self.controllers.release()
        manager = self.controller_manager
        if manager is not None and manager is not self:
            if manager.executor is not None:
                manager.executor.remove_node(manager)
            self.companion_nodes.remove(manager)
            manager.destroy_node()
            self.controller_manager = None
        self.features.remove_robot(self)
        self.simulation.remove_robot()

    def _build(self, physics_thread: bool, description: RobotDescription, *,
               from_topic: bool = False) -> None:
        """Build everything sim_node is for ``description``, in the steps of startup.py.

        Each step takes what it uses and returns what it makes, and the node
        keeps what it makes at once: an error in a later step then releases it
        (``destroy_node``).  The data passed orders most steps; three orders
        it does not show:

        * the recorder comes before the first publisher: ``create_publisher``
          and ``create_subscription`` tee into the bag what they make while it
          exists, so /clock, the state topics and TF are all recorded;
        * /clock's first stamp and the features' first samples (t = 0) leave
          before the ticks are made;
        * :meth:`_run` is last and starts the threads: every step that can
          fail has run by then, so a failed start-up leaves no thread running.
        """
        choice = startup.choose_controllers(self, description, self.settings,
                                            self._manager_settings, self._arguments)
        controllers, self._arguments = choice.config, choice.arguments
        topic_settings = choice.topic_settings
        topic_mode = topic_settings is not None
        self.robot_namespace = startup.robot_namespace(
            self.get_namespace(), self.settings.robot_namespace, controllers.namespace,
            description.plugin_namespace, is_controller_manager=self.is_controller_manager)
        self.simulation = startup.make_simulation(description, controllers, self.settings,
                                                  topic_mode=topic_mode, logger=self.get_logger())
        self.recorder = startup.make_recorder(self.settings, self.simulation,
                                              self.get_logger().warning)
        self._paused = self.settings.paused
        self.steps_run = 0  # physics steps this node has run (never reset; see run_steps)
        self._pacer = Pacer(self.settings.real_time_factor, self.settings.time_step)
        self.clock_publisher = ClockPublisher(
            self.create_publisher(Clock, CLOCK_TOPIC, QUEUE_DEPTH), self.simulation.time_step)
        self.gain_parameters = GainParameters(self)
        self._command_reader = startup.make_command_reader(self.context, self.turns,
                                                           self.get_logger())
        self.controllers = startup.bind_controllers(
            self, self.simulation, topic_settings, self.gain_parameters, self._command_reader,
            self.robot_namespace)
        self.topic_hardware = topic_hardware.TopicHardware(
            self, topic_settings, description, self.simulation.controllers) if topic_mode else None
        # Commands taken per controller (ignored ones included): a cheap health figure.
        self.commands_received = self.controllers.commands_received
        self.features = startup.make_features(
            self, self.simulation, self.robot_namespace, self.settings, world=self._world,
            from_topic=from_topic, is_controller_manager=self.is_controller_manager)
        self._add_controller_manager(startup.serve_controller_manager(
            self, self.controllers, self.simulation, controllers, self.settings, self._arguments,
            self.robot_namespace, topic_mode=topic_mode,
            is_controller_manager=self.is_controller_manager))
        self.clock_publisher.publish_newest(self.simulation.steps)
        self.features.after_steps()  # their first samples at t = 0, as /clock's
        self._make_ticks()
        self._offer_services()
        self._report(description, controllers)
        self._run()

    def _add_controller_manager(self, manager: Node | None) -> None:
        """Keep the node serving the controller_manager services; spin it if it is another."""
        self.controller_manager = manager
        if manager is None or manager is self:
            return
        self.companion_nodes.append(manager)
        if self.executor is not None:  # built once spinning (the description came late)
            self.executor.add_node(manager)

    def _make_ticks(self) -> None:
        """Make the physics thread (not started yet) or the executor's timer that runs the steps."""
        if self.turns is not None:
            self._physics_thread = PhysicsThread(self._on_tick, self._thread_period, self.turns)
        else:
            self._timer = self.create_timer(self._tick_period(), self._on_tick)

    def _offer_services(self) -> None:
        """Parameter callbacks, gazebo_ros's world services and simulation_interfaces."""
        # Checked in the on-set callback, applied in the post-set one: a change
        # that any callback refuses is applied nowhere.
        self.add_on_set_parameters_callback(self._check_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._world_services = services.create_world_services(
            self, reset=self.reset, set_paused=self.set_paused)
        # simulation_interfaces (where installed): its own module, its own callback groups.
        self.simulation_interfaces = simulation_services.create(self, self._world_services)

    def _report(self, description: RobotDescription, controllers: ControllersConfig) -> None:
        """Say once what runs, what is left out and why, and where to find it."""
        self._log_controllers(description, controllers)
        self._log_missing_interfaces()
        # Actuators, start positions, PyBullet's load messages, unstable gains.
        self.simulation.report_startup()
        clock_line = self.clock_publisher.period_line()
        if clock_line is not None:
            self.get_logger().info(clock_line)
        self.get_logger().info(
            f"simulating '{description.name}' from {description.source} "
            f"with {len(self.simulation.manager.active)} active controllers from "
            f"{controllers.label}; topics under "
            f"'{self.robot_namespace or '/'}', time_step {self.settings.time_step} s, "
            f'real_time_factor {self._pacer.real_time_factor}')
        if self.recorder is not None:
            self.get_logger().info(
                f"recording to '{self.recorder.folder}' (rosbag2, MCAP storage"
                f"{', sensors included' if self.settings.record_sensors else ''})")

    def _run(self) -> None:
        """Serve the view and start the threads; nothing may fail after the physics thread runs."""
        if self._viewer_settings.enabled:
            self._start_viewer(self._viewer_settings)
        if self._physics_thread is not None:
            if self._command_reader is not None:
                self._command_reader.start()
            self._physics_thread.start()

    def set_parameters(self, parameter_list: list[Parameter]) -> list[SetParametersResult]:
        """Set parameters; as the controller_manager, a spawner's ``<controller>.type`` too."""
        if self.is_controller_manager:
            drop_in.declare_controller_fields(self, parameter_list)
        return super().set_parameters(parameter_list)

    def set_parameters_atomically(self, parameter_list: list[Parameter]) -> SetParametersResult:
        """Set parameters at once (what the parameter services call); see set_parameters."""
        if self.is_controller_manager:
            drop_in.declare_controller_fields(self, parameter_list)
        return super().set_parameters_atomically(parameter_list)

    def _start_viewer(self, settings: view_feed.ViewerSettings) -> None:
        """Serve the browser view (its port was checked at the start of start-up)."""
        from pan_tilt_sim.ros.viewer import Viewer  # viser is imported only with the view

        camera = self.features.camera
        self.viewer = Viewer(self, settings, turns=self.turns,
                             extra_frames=tuple(self.features.robot_state.static_frames),
                             camera_image_topic=camera.image_topic if camera else None)
        self.get_logger().info(f'viewer: open {self.viewer.url} in a browser')

    def create_publisher(self, *args, **kwargs):
        """Create a publisher without rclpy's default QoS-event handler (see the design notes).

        While recording, the publisher is teed into the bag (a
        :class:`~pan_tilt_sim.ros.recording.RecordedPublisher`).
        """
        kwargs.setdefault('event_callbacks', PublisherEventCallbacks(use_default_callbacks=False))
        if self.bridged_topics is not None and len(args) >= 2:
            args = (*self.bridged_topics.publisher(args[0], args[1]), *args[2:])
        publisher = super().create_publisher(*args, **kwargs)
        return publisher if self.recorder is None else self.recorder.tee_publisher(publisher)

    def destroy_publisher(self, publisher) -> bool:
        """Destroy a publisher this node created (recorded or not)."""
        if isinstance(publisher, RecordedPublisher):
            publisher = publisher.publisher
        return super().destroy_publisher(publisher)

    def create_subscription(self, *args, **kwargs):
        """Create a subscription without rclpy's default QoS-event handler.

        Each default handler is one more waitable that rclpy's executor walks
        in Python at every wake-up, and sim_node has a subscription per
        command topic.  A peer with incompatible QoS is still warned about on
        the peer's side.
        """
        kwargs.setdefault('event_callbacks',
                          SubscriptionEventCallbacks(use_default_callbacks=False))
        if self.bridged_topics is not None and len(args) >= 3:
            args = (*self.bridged_topics.subscription(args[0], args[1], args[2]), *args[3:])
        subscription = super().create_subscription(*args, **kwargs)
        if self.recorder is not None:  # the messages received are recorded too
            self.recorder.tee_subscription(subscription)
        return subscription

    def topic(self, *names: str) -> str:
        """Absolute name of a topic of the robot."""
        return naming.join(self.robot_namespace, *names)

    def run_steps(self, steps: int) -> None:
        """Advance ``steps`` physics steps, publishing /clock and the features when due.

        /clock's stamps leave as :mod:`pan_tilt_sim.ros.clock_publisher` says;
        far above 10x real time use_sim_time timers see sim time advance in
        jumps of about a wall millisecond.

        At real_time_factor 0 a batch (about 5 ms of wall time) is cut at the
        stamps, so /clock advances through it; paced, a batch is a few ms of sim
        time run in a fraction of a wall millisecond, so its stamps leave
        together after it, back to back with the JointStates it took (see
        :class:`~pan_tilt_sim.ros.state_sinks.HeldSample`): right
        after the thread slept the first DDS publish is the dear one, and the
        ones right after it are cheap.  Up to 10x real time, /clock reaches a stamp before
        anything stamped at or after it leaves.  Nothing is published that nobody
        reads (see :meth:`_refresh_readers`).
        """
        simulation = self.simulation
        features = self.features
        controllers = self.controllers
        robots = list(self.spawned_robots.values())
        clock = self.clock_publisher
        clock_wanted = clock.wanted
        cut_at_stamps = clock_wanted and self._pacer.fast
        while steps > 0:
            # The steps run in chunks that end where something watched is due: a
            # /clock stamp that may leave now (factor 0), /tf, a camera frame, a
            # sensor sample.  Without a /clock token to spend (far above real
            # time) the next few stamps cannot leave anyway, so the chunk runs past them.
            step = simulation.steps
            chunk = steps
            if cut_at_stamps:
                chunk = min(chunk, clock.steps_to_stamp(step))
            due = features.steps_until_due(step)
            if due is not None:
                chunk = min(chunk, due)
            for robot in robots:
                due = robot.steps_until_due(step)
                if due is not None:
                    chunk = min(chunk, due)
            simulation.advance(chunk)
            self.steps_run += chunk
            steps -= chunk
            if clock_wanted:
                clock.publish_reached(step, chunk, cut_at_stamps)
            controllers.flush_joint_states()
            features.after_steps()
            for robot in robots:
                robot.flush_joint_states()
                robot.after_steps()
        clock.end_batch(simulation.steps)
        controllers.after_steps()
        for robot in robots:
            robot.after_batch()

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

    def step(self, steps: int) -> None:
        """Run ``steps`` steps now, paused or not (stepping on request, see stepping.py)."""
        self._refresh_readers()
        self.run_steps(steps)

    def reset(self, *, reset_time: bool = True, reset_state: bool = True) -> None:
        """Put the world back to its initial state; sim time to 0 if asked (/clock says so).

        The state is the robot's joints and controllers and the poses of the
        entities in the world (spawned objects stay; see simulation_services
        for more).  Every periodic publication (joint states, TF, camera)
        starts again from now.
        """
        if reset_state:
            self.simulation.reset(reset_time=reset_time)
            self.features.entities.reset_state()
        elif reset_time:
            self.simulation.reset_time()
        self._pacer.restart()
        self.clock_publisher.publish_newest(self.simulation.steps)
        self.features.reset()
        self.features.after_steps()
        for robot in self.spawned_robots.values():
            robot.reset()
            robot.after_steps()

    def destroy_node(self) -> None:
        """Stop the view and the ticking, destroy the controller_manager node, release PyBullet."""
        if self.viewer is not None:
            self.viewer.close()
        if self._physics_thread is not None:
            self._physics_thread.stop()
        if self._command_reader is not None:
            self._command_reader.stop()  # before the subscriptions it holds go
        if self._timer is not None:
            self._timer.cancel()
        if self.controllers is not None:
            # Samples a batch took before the physics stopped still leave (and reach a bag) --
            # unless a signal already shut the context down: then nothing can leave.
            if self.context.ok():
                try:
                    self.controllers.flush_joint_states()
                except RuntimeError:  # rclpy's RCLError: the context went in the meantime
                    pass
            self.controllers.destroy()
        while self.spawned_robots:
            self.spawned_robots.popitem()[1].destroy(release_topics=False)
        self._destroy_companions()
        if self.simulation_interfaces is not None:
            self.simulation_interfaces.close()
        if self.features is not None:
            self.features.close()
        if self.simulation is not None:
            self.simulation.close()
        if self.recorder is not None:  # last: everything that publishes has stopped
            self.recorder.close()
        logger = self.get_logger()
        super().destroy_node()
        # Once the node is gone: its rosout publisher may share a dead context.
        logger.debug('PyBullet disconnected, node destroyed')

    def _tick_period(self) -> float:
        # Paused, a zero-period timer would spin the CPU for nothing.
        return 0.0 if self._pacer.fast and not self._paused else TICK_PERIOD_S

    def _thread_period(self) -> float | None:
        """Wall seconds the physics thread waits before its next tick (None: until woken)."""
        if self._paused:
            return None
        return 0.0 if self._pacer.fast else TICK_PERIOD_S

    def _retime(self) -> None:
        """Give the ticks the period that the pace and the pause state call for."""
        if self._physics_thread is not None:
            self._physics_thread.wake()
            return
        period_ns = round(self._tick_period() * NANOSECONDS_PER_SECOND)
        if self._timer.timer_period_ns != period_ns:
            self._timer.timer_period_ns = period_ns
            self._timer.reset()

    def _on_tick(self) -> None:
        if self._paused:
            return
        steps = self._pacer.steps_due()
        if not steps:
            return
        if self._pacer.fast:
            self._refresh_readers()
            self.run_steps(steps)
        else:  # ask for the next batch, after publishing, while DDS's code is warm
            self.run_steps(steps)
            self._refresh_readers()

    def _refresh_readers(self) -> None:
        """Find out, once per batch, which of the periodic topics anybody reads.

        A publish costs CPU even with no subscriber, and asking is much cheaper
        -- except right after the physics thread slept between paced ticks,
        when DDS's code is cold: there the ticks ask after their batch, just
        after publishing, so a new subscriber is served from the batch after
        next (one or two ticks of wall time at factor 1, inside DDS's own
        matching delay).  At factor 0 and when
        stepping on request, they ask before the batch: a subscriber that the
        publisher has matched gets everything due from the next batch on.
        """
        self.clock_publisher.refresh_readers()
        self.controllers.refresh_readers()
        self.features.refresh_readers()
        for robot in self.spawned_robots.values():
            robot.refresh_readers()

    def _destroy_companions(self) -> None:
        while self.companion_nodes:
            self.companion_nodes.pop().destroy_node()

    def _log_missing_interfaces(self) -> None:
        """Say in one line which features are off because an interface package is missing."""
        missing = [package for package in ('control_msgs', 'controller_manager_msgs')
                   if self.topic_hardware is None and not optional_interfaces.available(package)]
        if self.simulation_interfaces is None:
            missing.append(simulation_services.PACKAGE)
        robot_state = self.features.robot_state
        if robot_state.tf_wanted and not robot_state.publishes_tf:
            missing.insert(0, 'tf2_msgs')
        line = optional_interfaces.missing_features_line(missing)
        if line:
            self.get_logger().info(line)

    def _log_controllers(self, description: RobotDescription,
                         controllers: ControllersConfig) -> None:
        """Say once what xacro warned about, and what is skipped, inactive or missing."""
        logger = self.get_logger()
        for warning in description.warnings:
            logger.warning(warning)
        manager = self.simulation.manager
        if not self.settings.autostart_controllers and self.topic_hardware is None:
            if self.controller_manager is not None:  # None: its Gazebo plugins run it
                logger.info(
                    f'no controller loaded: waiting for spawners at '
                    f"{self.controller_manager.get_fully_qualified_name()} (declared in "
                    f"{controllers.label}: {', '.join(manager.declared) or 'none'})")
            return
        for skipped in manager.skipped:
            logger.info(f"controller '{skipped.name}' (type '{skipped.type}') skipped: "
                        f'{skipped.reason}')
        for refusal in manager.refused.values():  # configured; this simulation cannot activate it
            logger.warning(refusal)
        inactive = [c.name for c in manager.controllers
                    if not manager.is_active(c.name) and c.name not in manager.refused]
        if inactive:
            logger.info(f"loaded but inactive (not in 'active_controllers'): "
                        f"{', '.join(inactive)}")
        every = [c for c in manager.controllers if isinstance(c, JointStateBroadcaster)]
        broadcasters = [c for c in every if not c.params['use_local_topics']]
        topic = self.topic('joint_states')
        if not broadcasters:
            # A Gazebo joint state publisher in the URDF publishes them instead.
            if not any(plugin.publishes_joint_states for plugin in self.simulation.plugins):
                local = [c.name for c in every]
                where = (f' publishes on {topic} (use_local_topics: {", ".join(local)})'
                         if local else '')
                logger.warning(
                    f'no joint_state_broadcaster in {controllers.label}{where}: nothing will '
                    f'be published on {topic}')
        elif not any(manager.is_active(c.name) for c in broadcasters):
            logger.warning(
                f"{', '.join(c.name for c in broadcasters)}: inactive (not in "
                f"'active_controllers'): nothing will be published on {topic}")

    @staticmethod
    def _own_updates(changed: list[Parameter]) -> dict:
        """Return the node's own parameters among ``changed``, coerced and checked."""
        updates = {p.name: parameters.runtime_value(p) for p in changed
                   if p.name in _OWN_PARAMETERS}  # other callbacks own the rest
        if 'real_time_factor' in updates:
            parameters.check_real_time_factor(updates['real_time_factor'])
        for name in parameters.PHYSICS_PARAMETERS:
            if name in updates:
                parameters.check_physics_setting(name, updates[name])
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
        physics = {name: updates[name] for name in parameters.PHYSICS_PARAMETERS
                   if name in updates}
        if physics:  # from the next step (callbacks run between batches of steps)
            settings = self.simulation.physics.settings
            self.simulation.physics.apply_settings(dataclasses.replace(settings, **physics))
