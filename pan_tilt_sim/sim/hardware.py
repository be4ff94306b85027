"""The ``<ros2_control>`` sensors and gpios, simulated: what fills their interfaces. No ROS.

Every ``<sensor>`` and ``<gpio>`` of the URDF's ``<ros2_control>`` blocks
gets its interfaces (:mod:`pan_tilt_sim.controllers.framework.hardware_interfaces`), which the
controllers claim by name as ros2_control's do.

**Sensors** are measured in the simulation's PyBullet client with the code
that measures the URDF's Gazebo sensors (:mod:`pan_tilt_sim.sim.sensors`),
at the place :func:`~pan_tilt_sim.model.control_sensors.placement` finds
(see that module for which interface names mean what) (see the design notes).

Design notes: docs/design/sim.md#hardwarepy.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy

from pan_tilt_sim.controllers.framework.hardware_interfaces import (
    CommandInterface,
    GpioHandle,
    HardwareInterfaces,
    SensorHandle,
    StateInterface,
)
from pan_tilt_sim.model import control_sensors as kinds
from pan_tilt_sim.model.control_sensors import Placement
from pan_tilt_sim.model.robot import (
    ControlGpio,
    ControlSensor,
    ControlSystem,
    JointSpec,
    RobotModel,
)
from pan_tilt_sim.model.sensors import (
    CHILD,
    CHILD_TO_PARENT,
    NO_NOISE,
    RaySpec,
    SensorKind,
    SensorSpec,
    sensor_interface,
)
from pan_tilt_sim.model.transforms import rotation_matrix
from pan_tilt_sim.schedule import PeriodicSchedule
from pan_tilt_sim.sim.physics import Physics
from pan_tilt_sim.sim.sensors.force_torque import ForceTorque
from pan_tilt_sim.sim.sensors.imu import Imu
from pan_tilt_sim.sim.sensors.lidar import Lidar
from pan_tilt_sim.sim.sensors.mount import LinkReader, inverse
from pan_tilt_sim.sim.sensors.noise import NoiseModel, generator

INFO, WARNING = 'info', 'warning'
DEFAULT_MAX_RANGE = 100.0  # m: how far a range sensor without limits looks
NOISE_STREAM_OFFSET = 1000  # noise generator indices of ros2_control sensors start here
MOCK_GPIO_COMMANDS = 'mock_gpio_commands'
DEFAULT_WORLD = 'empty'  # until the node says which scenery the rays may meet
WORLD_FRAME = 'world'  # a pose in the simulation's world frame, as a frame_id may name it
TRUE_TEXTS = ('true', '1', 'on', 'yes')


def _interfaces(names: tuple[str, ...]) -> tuple[str, str, str]:
    """Return how a line names ``names``: (state interface(s) x, y; is/are; it/they)."""
    if len(names) == 1:
        return f'state interface {names[0]}', 'is', 'it'
    return f"state interfaces {', '.join(names)}", 'are', 'they'


def _keeps(pronoun: str) -> str:
    return f"{pronoun} {'keeps its' if pronoun == 'it' else 'keep their'} initial_value"


class _Context:
    """What every simulated sensor shares: the physics, the model, the clock, world and seed."""

    def __init__(self, physics: Physics, model: RobotModel, steps: Callable[[], int]) -> None:
        self.physics = physics
        self.model = model
        self.steps = steps
        self.world = DEFAULT_WORLD
        self.seed: int | None = None
        self.links = set(model.link_names)


class SimulatedSensor:
    """Fills one ``<sensor>``'s interfaces from the physics (a ``SensorSource``)."""

    def __init__(self, context: _Context, control: ControlSensor, index: int,
                 placed: Placement | None) -> None:
        self._context = context
        self.control = control
        self._index = index
        self.placement = placed
        self.wrench = kinds.measures(control, kinds.WRENCH)
        self.imu = kinds.reads_imu(control)
        self.pose = kinds.measures(control, kinds.POSITION)
        self.range = kinds.measures(control, kinds.RANGE)
        self._frame: str | None = None  # the broadcaster's frame_id, where it applies
        self._watched = False
        self._valid_from = 0  # the first step at which a wrench reading is valid
        self._written = False
        self._force_torque: ForceTorque | None = None
        self._imu: Imu | None = None
        self._lidar: Lidar | None = None
        self._link: LinkReader | None = None
        self._reference: LinkReader | None = None
        self._child: LinkReader | None = None
        self._target: LinkReader | None = None
        self._schedule: PeriodicSchedule | None = None
        self.problem = ''  # why something it has cannot be measured where it is
        self.rebuild()

    # --- where it is and what measures it ----------------------------------------------------

    @property
    def gazebo(self) -> SensorSpec | None:
        """The Gazebo sensor of the same name, if the URDF has one."""
        return None if self.placement is None else self.placement.gazebo

    def joint(self) -> JointSpec | None:
        """Return the joint whose reaction the wrench is (None: no joint above the link)."""
        gazebo = self.gazebo
        if gazebo is not None and gazebo.kind is SensorKind.FORCE_TORQUE:
            return self._context.model.joint(gazebo.joint)
        return self._context.model.parent_joint(self.placement.link)

    def frame_name(self) -> str:
        """Return the frame the readings are given in when no broadcaster asks for another."""
        gazebo = self.gazebo
        if gazebo is not None:
            return sensor_interface(gazebo, self._context.model.name).frame_id
        return self.placement.link

    @property
    def feedback_on(self) -> bool:
        """Whether this sensor has PyBullet's joint feedback on (it costs every step)."""
        return self._force_torque is not None and self._force_torque.enabled

    def release(self) -> None:
        """Drop the readers, switching off the joint feedback this sensor switched on."""
        if self._force_torque is not None:
            self._force_torque.enable(False)
        self._force_torque = self._imu = self._lidar = None
        self._link = self._reference = self._child = self._target = None

    def rebuild(self) -> None:
        """Make the readers for the placement, the frame asked for, the world and the seed."""
        self.release()
        self.problem = ''
        placed = self.placement
        if placed is None:
            return
        context = self._context
        physics = context.physics
        rng = generator(context.seed, NOISE_STREAM_OFFSET + self._index)
        gazebo = placed.gazebo
        interface = None if gazebo is None else sensor_interface(gazebo, context.model.name)
        rate = 0.0 if interface is None else interface.rate
        self._schedule = PeriodicSchedule(1.0 / rate) if rate > 0.0 else None
        extra = 0.0 if interface is None else interface.noise_stddev
        name = self.control.name
        self._link = LinkReader(physics, placed.link)
        if self.wrench:
            self._build_wrench(gazebo, interface, rng, extra)
        if self.imu:
            spec = gazebo if gazebo is not None and gazebo.kind is SensorKind.IMU else SensorSpec(
                name=name, type='imu', kind=SensorKind.IMU, link=placed.link, pose=placed.pose)
            imu = spec.imu
            self._imu = Imu(
                physics, spec,
                orientation_from_start=interface is not None and spec is gazebo
                and interface.orientation_from_start,
                angular_noise=None if imu is None else NoiseModel(imu.angular_velocity_noise,
                                                                  rng, extra),
                linear_noise=None if imu is None else NoiseModel(
                    imu.linear_acceleration_noise, rng, extra),
                orientation_stddev=extra if spec is gazebo else 0.0, rng=rng)
        if self.range:
            ray = gazebo.ray if gazebo is not None and gazebo.ray is not None else None
            params = self.control.params
            low = ray.range_min if ray else _number(params.get('min_range'), 0.0)
            high = ray.range_max if ray else _number(params.get('max_range'), DEFAULT_MAX_RANGE)
            beam = RaySpec(range_min=low, range_max=high, noise=ray.noise if ray else NO_NOISE)
            spec = SensorSpec(name=name, type='ray', kind=SensorKind.LIDAR, link=placed.link,
                              pose=placed.pose, ray=beam)
            self._lidar = Lidar(physics, spec, context.world,
                                NoiseModel([beam.noise], rng, extra))
        if self.pose and self._frame in context.links:
            self._reference = LinkReader(physics, self._frame)
        if self._watched and self._force_torque is not None:
            self._force_torque.enable(True)
            self._valid_from = context.steps() + 1  # its feedback was switched off and on

    def _build_wrench(self, gazebo: SensorSpec | None, interface, rng, extra: float) -> None:
        joint = self.joint()
        if joint is None:
            self.problem = (f"'{self.placement.link}' is the root link: no joint above it "
                            'carries a load to measure; force and torque read NaN')
            return
        physics = self._context.physics
        if gazebo is not None and gazebo.kind is SensorKind.FORCE_TORQUE:
            spec, frame, direction = gazebo, interface.wrench_frame, interface.measure_direction
            noises = (*gazebo.force_torque.force_noise, *gazebo.force_torque.torque_noise) \
                if gazebo.force_torque is not None else ()
        else:
            spec = SensorSpec(name=self.control.name, type='force_torque',
                              kind=SensorKind.FORCE_TORQUE, link=joint.child, joint=joint.name,
                              parent_link=joint.parent)
            frame, direction, noises = CHILD, CHILD_TO_PARENT, ()
        noise = NoiseModel(noises or [NO_NOISE] * len(kinds.WRENCH), rng, extra)
        express = self._frame is not None and self._frame in self._context.links and (
            self._frame != self.frame_name())
        if express:  # the child's frame, then moved to the frame asked for
            frame = CHILD
            self._child = LinkReader(physics, joint.child)
            self._target = LinkReader(physics, self._frame)
        self._force_torque = ForceTorque(physics, spec, joint, frame=frame,
                                         measure_direction=direction, noise=noise,
                                         enabled=False)

    # --- SensorSource --------------------------------------------------------------------------

    def set_watched(self, watched: bool) -> None:
        """Switch the joint feedback on while watched; the next reading is not valid yet."""
        if watched == self._watched:
            return
        self._watched = watched
        if self._force_torque is not None:
            self._force_torque.enable(watched)
        if watched:
            self._valid_from = self._context.steps() + 1
            if self._imu is not None:
                self._imu.forget()

    def use_frame(self, frame: str) -> str | None:
        """Place an unplaced sensor at ``frame``, or give the wrench / pose there."""
        links = self._context.links
        if self.placement is None:
            if self.pose:  # the frame the pose is given in, not where the sensor is:
                self._frame = frame  # the start-up warning said it reads NaN
                return None
            if frame not in links:
                return (f"is not a link of the robot, and nothing in the URDF places sensor "
                        f"'{self.control.name}': it reads NaN")
            self.placement = Placement(frame, via="its broadcaster's frame_id")
            self._frame = frame
            self.rebuild()
            return self.problem or None
        if frame == self._frame:
            return None
        self._frame = frame
        self.rebuild()
        problems = [self.problem] if self.problem else []
        own = self.frame_name()
        if self.wrench and frame != own and frame not in links:
            problems.append(f"is not a link of the robot: the wrench is given in '{own}'")
        if (self.imu or self.range) and frame not in (own, self.placement.link):
            problems.append(f"sensor '{self.control.name}' is on '{self.placement.link}' "
                            f'({self.placement.via}): its readings are measured there')
        if self.pose and frame not in links and frame != WORLD_FRAME:
            problems.append('is not a link of the robot: the pose is given in the world')
        return '; '.join(problems) or None

    def reset(self) -> None:
        """Sim time went back: readings start afresh (the next one is not valid yet)."""
        self._written = False
        self._valid_from = self._context.steps() + 1
        if self._imu is not None:
            self._imu.forget()
        if self._schedule is not None:
            self._schedule.reset()

    def write(self, handle: SensorHandle, time: float) -> bool:
        """Measure at sim ``time`` and write the readings; False while one is not valid yet."""
        if self.placement is None:
            return True
        schedule = self._schedule
        if self._written and schedule is not None and not schedule.is_due(time):
            return True  # between a Gazebo sensor's updates its readings stay
        step = round(time / self._context.physics.time_step)
        values: dict[str, float] = {}
        valid = True
        if self._force_torque is not None:
            if step < self._valid_from:
                valid = False
            else:
                force, torque = self._wrench()
                values.update(zip(kinds.FORCE, force, strict=True))
                values.update(zip(kinds.TORQUE, torque, strict=True))
        if self._imu is not None:
            if not self._imu.has_earlier(step):
                self._imu.remember(step)
                valid = False
            else:
                reading = self._imu.read(step)
                values.update(zip(kinds.ORIENTATION, reading.orientation, strict=True))
                values.update(zip(kinds.ANGULAR_VELOCITY, reading.angular_velocity,
                                  strict=True))
                values.update(zip(kinds.LINEAR_ACCELERATION, reading.linear_acceleration,
                                  strict=True))
        if self.pose:
            pose = self._link.frame().then(self.placement.pose)
            if self._reference is not None:
                pose = inverse(self._reference.frame()).then(pose)
            values.update(zip(kinds.POSITION, pose.translation, strict=True))
            if not self.imu:
                values.update(zip(kinds.ORIENTATION, pose.rotation, strict=True))
        if self._lidar is not None:
            values['range'] = float(self._lidar.scan()[0, 0])
        if not valid:
            return False
        interfaces = handle.interfaces
        for name, value in values.items():
            interface = interfaces.get(name)
            if interface is not None:
                interface.value = float(value)
        self._written = True
        if schedule is not None:
            schedule.advance(time)
        return True

    def _wrench(self) -> tuple[numpy.ndarray, numpy.ndarray]:
        """Return the wrench as the sensor reports it, or moved into the frame asked for."""
        wrench = self._force_torque.read()
        if self._target is None:
            return wrench.force, wrench.torque
        child, target = self._child.frame(), self._target.frame()
        to_world = numpy.array(rotation_matrix(child.rotation))
        to_target = numpy.array(rotation_matrix(target.rotation)).T
        force = to_world @ wrench.force
        lever = numpy.array(child.translation) - numpy.array(target.translation)
        torque = to_world @ wrench.torque + numpy.cross(lever, force)
        return to_target @ force, to_target @ torque

    # --- what it says at start-up ------------------------------------------------------------

    def describe(self) -> list[tuple[str, str]]:
        """Return the start-up lines about this sensor: what it measures where, what it cannot."""
        name = self.control.name
        lines = []
        unsimulated = kinds.unsimulated(self.control)
        if unsimulated:
            listed, verb, pronoun = _interfaces(unsimulated)
            lines.append((WARNING, f"sensor '{name}': {listed} {verb} not simulated: "
                                   f'{_keeps(pronoun)} (NaN where none is given)'))
        if self.placement is None:
            if len(unsimulated) < len(self.control.state_interfaces):
                lines.append((WARNING, f"sensor '{name}' is not placed: "
                                       f'{kinds.unplaced_reason(self.control)}'))
            return lines
        if self.problem:
            lines.append((WARNING, f"sensor '{name}': {self.problem}"))
        measured = []
        if self._force_torque is not None:
            joint = self._force_torque.sensor.joint
            unloaded = kinds.carried_mass(self._context.model,
                                          self._context.model.joint(joint).child) <= 0.0
            measured.append(f"the wrench on joint '{joint}'" + (
                ' (nothing beyond it has mass: 0 until something pushes on it)'
                if unloaded else ''))
        if self._imu is not None:
            measured.append('an IMU')
        if self.pose:
            measured.append('the pose')
        if self._lidar is not None:
            measured.append(f'a range ray of {self._lidar.ray.range_max:g} m')
        if measured:
            lines.append((INFO, f"sensor '{name}': {', '.join(measured)} at "
                                f"'{self.placement.link}' ({self.placement.via})"))
        return lines


def _number(text: str | None, default: float) -> float:
    """Return a ``<param>`` number; ``default`` where it is absent or not a finite number."""
    try:
        value = float(text) if text is not None else default
    except ValueError:
        return default
    return value if math.isfinite(value) else default


def _gpio(gpio: ControlGpio, system: ControlSystem) -> tuple[GpioHandle, list[tuple[str, str]]]:
    """Build a gpio's interfaces, commands echoed into same-named states; say what it does."""
    name = gpio.name
    states = {interface.name: StateInterface(f'{name}/{interface.name}',
                                             interface.initial_value)
              for interface in gpio.state_interfaces}
    commands = list(gpio.command_interface_names)
    if system.hardware_params.get(MOCK_GPIO_COMMANDS, '').strip().lower() in TRUE_TEXTS:
        commands += [state for state in states if state not in commands]
    handle = GpioHandle(name, [CommandInterface(f'{name}/{command}', states.get(command))
                               for command in dict.fromkeys(commands)], states.values())
    lines = []
    echoed = tuple(command for command in handle.commands if command in states)
    if echoed:
        lines.append((INFO, f"gpio '{name}': {', '.join(echoed)}: a command is echoed into the "
                            'state interface of its name, as mock hardware echoes it'))
    inputs = tuple(state for state in states if state not in handle.commands)
    if inputs:
        listed, verb, pronoun = _interfaces(inputs)
        has = 'has' if verb == 'is' else 'have'
        lines.append((WARNING, f"gpio '{name}': {listed} {has} no command interface to echo "
                               'and nothing in the simulation drives '
                               f"{'it' if pronoun == 'it' else 'them'}: {_keeps(pronoun)} "
                               "(NaN where none is given), as mock hardware's do"))
    return handle, lines


class SimulatedHardware:
    """The robot's ``<ros2_control>`` sensors and gpios, filled by the simulation."""

    def __init__(self, physics: Physics, model: RobotModel, steps: Callable[[], int]) -> None:
        self._context = _Context(physics, model, steps)
        self.sensors: list[SimulatedSensor] = []
        sensors = []
        for index, control in enumerate(model.control_sensors):
            handle = SensorHandle(control.name, [
                StateInterface(f'{control.name}/{interface.name}', interface.initial_value)
                for interface in control.state_interfaces])
            source = SimulatedSensor(self._context, control, index,
                                     kinds.placement(model, control))
            handle.attach(source)
            self.sensors.append(source)
            sensors.append(handle)
        gpios = []
        self._gpio_lines: list[tuple[str, str]] = []
        for system in model.ros2_control:
            for gpio in system.gpios:
                handle, lines = _gpio(gpio, system)
                gpios.append(handle)
                self._gpio_lines += lines
        self.interfaces = HardwareInterfaces(sensors, gpios)

    def configure(self, *, world: str = DEFAULT_WORLD, seed: int | None = None) -> None:
        """Say which scenery range rays may meet (its ground) and the noise seed (None: OS)."""
        context = self._context
        if (world, seed) == (context.world, context.seed):
            return
        context.world, context.seed = world, seed
        for sensor in self.sensors:
            sensor.rebuild()

    def reset(self) -> None:
        """Every interface back to its initial value; sensors start afresh."""
        self.interfaces.reset()

    def startup_report(self) -> list[tuple[str, str]]:
        """Return ``(level, line)`` for every sensor and gpio: what is simulated, what is not."""
        lines = []
        for sensor in self.sensors:
            lines += sensor.describe()
        return lines + self._gpio_lines

    def close(self) -> None:
        """Switch off what the sensors switched on in PyBullet."""
        for sensor in self.sensors:
            sensor.release()
