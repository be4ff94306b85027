"""The simulation loop: physics and controllers, stepped together, no ROS.

Each step is ros2_control's read / update / write around one physics step:
the measured joint states go into the joint handles, every active controller
updates (command controllers first, so broadcasters sample fresh efforts),
the efforts go to PyBullet, and PyBullet advances one ``time_step``.  Sim
time is kept as a step count, so it never accumulates rounding error.
Which controllers are loaded and which are active is the
:class:`~pan_tilt_sim.controllers.manager.ControllerManager`'s business.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from pan_tilt_sim.controllers import CommandController, Controller, JointHandle
from pan_tilt_sim.controllers.manager import ControllerManager
from pan_tilt_sim.model.controller_config import ControllersConfig
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.sim.physics import STATE_POSITION, STATE_VELOCITY, Physics


class Simulation:
    """One robot in PyBullet, driven by its controllers, advanced step by step."""

    def __init__(self, description: RobotDescription, controllers: ControllersConfig,
                 time_step: float, *, gui: bool = False,
                 active_controllers: Sequence[str] | None = None) -> None:
        self.description = description
        self.physics = Physics(description, time_step, gui=gui)
        try:
            self.handles = {joint.name: JointHandle(joint) for joint in self.physics.joints}
            self.manager = ControllerManager(controllers, self.handles, description.model,
                                             active=active_controllers)
            self.controllers = self.manager.controllers
        except BaseException:
            self.physics.close()
            raise
        self._handle_list = list(self.handles.values())
        self._efforts = [0.0] * len(self._handle_list)
        self._time_step = time_step
        self._steps = 0
        self._states = self.physics.read_states()
        self._physics_step = self.physics.stepper()

    @property
    def time_step(self) -> float:
        """Seconds of sim time per step."""
        return self._time_step

    @property
    def steps(self) -> int:
        """Steps taken since the start (or the last reset of time)."""
        return self._steps

    @property
    def time(self) -> float:
        """Sim time in seconds."""
        return self._steps * self._time_step

    def command_controllers(self) -> list[CommandController]:
        """Return the (loaded) controllers that take commands from topics."""
        return [c for c in self.controllers if isinstance(c, CommandController)]

    def controller(self, name: str) -> Controller:
        """Return the controller called ``name``; KeyError if there is none."""
        for controller in self.controllers:
            if controller.name == name:
                return controller
        raise KeyError(name)

    def advance(self, steps: int) -> None:
        """Run ``steps`` physics steps, updating every active controller at each."""
        # Everything the loop touches is a local: bound methods, the physics
        # stepper, the handles.  Per step this costs ~1 us of Python for the
        # pan/tilt against ~5 us inside PyBullet (see README, Performance).
        handles = self._handle_list
        updates = self.manager.updates
        efforts = self._efforts
        physics_step = self._physics_step
        dt = self._time_step
        states = self._states
        first = self._steps
        for count in range(first, first + steps):
            # Equal lengths by construction; strict=True would cost ~0.2 us per step.
            for handle, state in zip(handles, states, strict=False):
                handle.position = state[STATE_POSITION]
                handle.velocity = state[STATE_VELOCITY]
            time = count * dt
            for update in updates:
                update(time, dt)
            for index, handle in enumerate(handles):
                efforts[index] = handle.effort
            states = physics_step(efforts)
        self._steps = first + steps
        self._states = states

    def reset(self, *, reset_time: bool = True) -> None:
        """Joints back to their initial state, controllers reset; sim time to 0 if asked."""
        for handle in self._handle_list:
            handle.reset()
        self.physics.reset_joints([handle.position for handle in self._handle_list])
        self._states = self.physics.read_states()
        for controller in self.controllers:
            controller.reset()
        if reset_time:
            self._steps = 0

    def reset_time(self) -> None:
        """Sim time back to 0, the joints left where they are; controllers hold them there.

        Controllers are reset as after a start (commands and trajectories,
        timed on the old clock, are dropped; position controllers hold the
        present position).
        """
        for controller in self.controllers:
            controller.reset()
        self._steps = 0

    def joint_positions(self) -> dict[str, float]:
        """Return the measured position of every movable joint, by name."""
        return {name: state[STATE_POSITION]
                for name, state in zip(self.handles, self._states, strict=True)}

    def joint_velocities(self) -> dict[str, float]:
        """Return the measured velocity of every movable joint, by name."""
        return {name: state[STATE_VELOCITY]
                for name, state in zip(self.handles, self._states, strict=True)}

    def close(self) -> None:
        """Release PyBullet."""
        self.physics.close()

    def __enter__(self) -> Simulation:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def make_simulation(description_file: str, controllers_file: str | None, time_step: float, *,
                    xacro_args: Sequence[str] = (), gui: bool = False,
                    controllers_args: Mapping[str, str] | None = None,
                    active_controllers: Sequence[str] | None = None) -> Simulation:
    """Load both files and build a :class:`Simulation` (for tools and tests).

    Without ``controllers_file`` the URDF's control plugin names it (see
    :func:`~pan_tilt_sim.model.controller_config.controllers_files_for`).
    """
    from pan_tilt_sim.model.controller_config import (
        controllers_files_for,
        load_controllers_config,
    )
    from pan_tilt_sim.model.description import load_description

    description = load_description(description_file, xacro_args)
    files = controllers_files_for(str(controllers_file or ''), description)
    return Simulation(description, load_controllers_config(files, controllers_args), time_step,
                      gui=gui, active_controllers=active_controllers)
