"""Controllers on their own clock, as ros2_control runs them, inside the stepping loop.

A ros2_control style file's controllers update every ``1 / update_rate`` s
of sim time with that period as their ``dt``; the physics steps at
``time_step`` in between and the joints keep the held commands; an ideal
actuator still tracks its held setpoint every physics step, as
gz_ros2_control's write does.  A ROS 1 file's controllers update at every
physics step.  A rate whose period is not a whole number of steps updates at
the first step where its period has passed, and the start-up log says so.
The compiled laws follow the same clocks to the last bit.
"""

import math

import pytest
from robot_fixtures import JointDef, write_star_robot, write_text

from pan_tilt_sim.sim import compiled_step
from pan_tilt_sim.sim.engine import INFO, WARNING, make_simulation

TIME_STEP = 0.001
JOINTS = [JointDef('a', damping=0.0, effort=20.0, velocity=3.0),
          JointDef('b', damping=0.0, effort=20.0, velocity=3.0)]
P, I_GAIN, D = 40.0, 30.0, 2.0


def ros2_file(rate: float, own: str = '', *, gains: bool = True) -> str:
    pid = f'pid: {{p: {P}, i: {I_GAIN}, d: {D}}}' if gains else ''
    package = 'effort_controllers' if gains else 'position_controllers'  # the latter: ideal
    return f"""
    controller_manager:
      ros__parameters:
        update_rate: {rate}
        pos:
          type: {package}/JointPositionController
    pos:
      ros__parameters:
        joint: a
        {pid}
        {own}
    """


class Log:
    """A logger that keeps what the simulation logs: (level, message)."""

    def __init__(self):
        self.lines = []

    def info(self, message):
        self.lines.append((INFO, message))

    def warning(self, message):
        self.lines.append((WARNING, message))


def simulation_of(folder, controllers: str, switch: str = '1', log: Log | None = None):
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv(compiled_step.ENVIRONMENT_SWITCH, switch)
        urdf = write_star_robot(folder, JOINTS)
        path = write_text(folder, 'controllers.yaml', controllers)
        return make_simulation(str(urdf), str(path), TIME_STEP, logger=log)


def record(simulation, steps: int, command: float = 0.5) -> list[tuple[float, float, float]]:
    """Step one at a time; return (position, velocity) each step starts from, and the effort."""
    simulation.controller('pos').set_command(command)
    rows = []
    for _ in range(steps):
        state = simulation.joint_positions()['a'], simulation.joint_velocities()['a']
        simulation.advance(1)
        rows.append((*state, simulation.handles['a'].effort))
    return rows


def hand_computed_efforts(rows, every: int, dt: float, command: float = 0.5) -> list[float]:
    """The position PID by hand: updates at steps 0, every, 2 every..., its effort held."""
    max_step = 3.0 * dt  # the velocity limit's ramp, per update
    setpoint, integral, effort = 0.0, 0.0, math.nan
    efforts = []
    for step, (position, velocity, _) in enumerate(rows):
        if step % every == 0:
            setpoint = min(command, setpoint + max_step)
            error = setpoint - position
            integral += I_GAIN * error * dt
            effort = max(-20.0, min(20.0, P * error + integral - D * velocity))
        efforts.append(effort)
    return efforts


def test_a_pid_at_100_hz_on_a_1_khz_physics_updates_every_10_steps_with_dt_0_01(tmp_path):
    with simulation_of(tmp_path, ros2_file(100)) as simulation:
        rows = record(simulation, 35)
    efforts = [effort for _, _, effort in rows]
    assert efforts == pytest.approx(hand_computed_efforts(rows, 10, 0.01), rel=1e-12, abs=0)
    # Held between updates: exactly four different efforts in 35 steps, each ten steps long.
    assert efforts[0:10] == [efforts[0]] * 10 and efforts[10:20] == [efforts[10]] * 10
    assert len(set(efforts)) == 4


def test_the_controllers_own_update_rate_wins_over_the_managers(tmp_path):
    with simulation_of(tmp_path, ros2_file(100, 'update_rate: 250')) as simulation:
        assert simulation.manager.update_rate_of('pos') == 250.0
        rows = record(simulation, 20)
    efforts = [effort for _, _, effort in rows]
    assert efforts == pytest.approx(hand_computed_efforts(rows, 4, 0.004), rel=1e-12, abs=0)


def test_a_ros1_file_updates_at_every_physics_step_with_the_physics_dt(tmp_path):
    ros1 = f"""
    pos:
      type: effort_controllers/JointPositionController
      joint: a
      pid: {{p: {P}, i: {I_GAIN}, d: {D}}}
    """
    with simulation_of(tmp_path, ros1) as simulation:
        assert simulation.manager.update_rate_of('pos') is None
        rows = record(simulation, 12)
    efforts = [effort for _, _, effort in rows]
    assert efforts == pytest.approx(hand_computed_efforts(rows, 1, TIME_STEP), rel=1e-12, abs=0)


def test_a_rate_that_does_not_divide_the_physics_rate_updates_when_its_period_has_passed(
        tmp_path):
    log = Log()
    with simulation_of(tmp_path, ros2_file(300), log=log) as simulation:
        rows = record(simulation, 13)
    notes = [message for level, message in log.lines if 'update_rate 300 Hz' in message]
    # 1/300 s has passed after 4 steps (4 ms): updates at 0, 4, 8, 12 with dt 0.004.
    efforts = [effort for _, _, effort in rows]
    assert efforts == pytest.approx(hand_computed_efforts(rows, 4, 0.004), rel=1e-12, abs=0)
    assert len(notes) == 1, log.lines
    assert notes[0].startswith('update_rate 300 Hz of pos is not a whole number of physics '
                               'steps (0.001 s): updates every 4 steps, 250 Hz (period 0.004 s)')


def test_a_rate_that_divides_the_physics_rate_gets_no_start_up_line(tmp_path):
    log = Log()
    with simulation_of(tmp_path, ros2_file(100), log=log):
        pass
    assert log.lines and not [message for _, message in log.lines if 'update_rate' in message]


def positions_of(folder, controllers: str, command_at: int, steps: int) -> list[str]:
    """Command 0.5 rad at step ``command_at``; return the joint's positions each step (hex)."""
    positions = []
    with simulation_of(folder, controllers) as simulation:
        for step in range(steps):
            if step == command_at:
                simulation.controller('pos').set_command(0.5)
            simulation.advance(1)
            positions.append(simulation.joint_positions()['a'].hex())
    return positions


def test_an_ideal_actuator_ramps_and_tracks_the_held_command_at_every_physics_step(tmp_path):
    # The hardware's part runs every physics step: a command the 100 Hz controller takes at
    # step 0 moves the joint exactly as one taken by a controller at the physics rate.
    every_step = positions_of(tmp_path, ros2_file(1000, gains=False), 0, 300)
    assert positions_of(tmp_path, ros2_file(100, gains=False), 0, 300) == every_step
    # A command arriving at step 5 is taken at the next update, step 10.
    late = positions_of(tmp_path, ros2_file(100, gains=False), 5, 310)
    assert late[:10] == [late[0]] * 10 and late[10:] == every_step
    assert positions_of(tmp_path, ros2_file(1000, gains=False), 5, 310)[10:] != every_step


def test_a_reset_or_an_activation_makes_the_controller_update_at_the_next_step(tmp_path):
    with simulation_of(tmp_path, ros2_file(100)) as simulation:
        handle = simulation.handles['a']
        simulation.controller('pos').set_command(0.5)
        simulation.advance(7)
        simulation.reset(reset_time=False)  # the effort is 0 until the controller updates
        simulation.controller('pos').set_command(0.5)
        simulation.advance(1)  # step 7: due at once, not at step 10
        first = handle.effort
        assert first != 0.0
        simulation.advance(9)
        assert handle.effort == first  # held through step 16
        simulation.advance(4)  # updated at step 17; now at step 21
        held = handle.effort
        assert held != first
        simulation.manager.switch(deactivate=['pos'])
        simulation.manager.switch(activate=['pos'])
        simulation.advance(1)  # step 21: updated at once, not at step 27
        assert handle.effort != held


def test_the_gain_check_uses_the_controllers_own_period(tmp_path):
    # Stable at 1 kHz (d dt / 2 = 0.001 kg m^2 for J ~ 0.003); at 10 Hz the held effort
    # overshoots: d T / 2 = 0.1.
    gains = 'pid: {p: 10.0, i: 0.0, d: 2.0}'
    log = Log()
    with simulation_of(tmp_path, f"""
    pos:
      type: effort_controllers/JointPositionController
      joint: a
      {gains}
    """, log=log):
        pass
    assert log.lines and not [message for _, message in log.lines if 'unstable' in message]
    log = Log()
    with simulation_of(tmp_path, ros2_file(10).replace(
            f'pid: {{p: {P}, i: {I_GAIN}, d: {D}}}', gains), log=log):
        pass
    warnings = [message for level, message in log.lines
                if level == WARNING and 'unstable' in message]
    assert len(warnings) == 1
    assert warnings[0].startswith("joint 'a' (pos): PID p 10 d 2 is unstable at its update "
                                  'period 0.1 s (100 physics steps, the effort held in between)')


def samples_both_ways(folder, controllers: str) -> tuple:
    """Run the controllers in C and in Python; return the joint states after each batch."""
    results = []
    for switch in ('1', '0'):
        with simulation_of(folder, controllers, switch) as simulation:
            states = []
            for index, batch in enumerate((1, 3, 17, 250, 729, 5, 1000)):
                simulation.controller('pos').set_command(0.5 if index % 2 else -0.3)
                simulation.controller('vel').set_command(2.0 if index % 2 else -1.0)
                simulation.advance(batch)
                states.append(([value.hex() for value in simulation.joint_positions().values()],
                               [handle.effort.hex() for handle in simulation.handles.values()]))
            results.append((states, simulation.compiled_steps))
    return results


@pytest.mark.parametrize('rate', [100, 300, 1000, 2000])
def test_the_compiled_laws_follow_the_controllers_clocks_to_the_last_bit(tmp_path, rate):
    controllers = f"""
    controller_manager:
      ros__parameters:
        update_rate: {rate}
        jsb: {{type: joint_state_broadcaster/JointStateBroadcaster}}
        pos: {{type: effort_controllers/JointPositionController}}
        vel: {{type: effort_controllers/JointVelocityController}}
    jsb:
      ros__parameters: {{publish_rate: 50.0}}
    pos:
      ros__parameters:
        joint: a
        pid: {{p: {P}, i: {I_GAIN}, d: {D}}}
    vel:
      ros__parameters:
        joint: b
        update_rate: 70
        pid: {{p: 3.0, i: 1.0, d: 0.0}}
    """
    (compiled, in_c), (python, in_python) = samples_both_ways(tmp_path, controllers)
    assert in_python == 0 and in_c > 1500
    assert compiled == python


def test_the_start_up_line_is_information(tmp_path):
    log = Log()
    with simulation_of(tmp_path, ros2_file(300), log=log):
        pass
    assert {level for level, message in log.lines if 'update_rate' in message} == {INFO}
