"""Which command interfaces a ``<ros2_control>`` block's hardware lets controllers start.

Before a controller switch starts or stops command interfaces, ros2_control
asks every hardware component whose interfaces are among them whether it
accepts the new combination (``prepare_command_mode_switch``, handed only
that component's own interfaces); if one refuses, controller_manager refuses
the whole switch: "Could not switch controllers since prepare command mode
switch was rejected."  A switch touching no command interface (a broadcaster
alone) asks no component.

The simulator drives every joint with its own physics, whatever the block's
``<plugin>`` says.  What it refuses is decided by that plugin, as the
hardware would decide (see the design notes).

Design notes: docs/design/model.md#command_modespy.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence

from pan_tilt_sim.model.robot import ControlSystem

# controller_manager's message when a component refuses the combination.
SWITCH_REJECTED = 'Could not switch controllers since prepare command mode switch was rejected'
MOCK_PLUGIN = 'mock_components/GenericSystem'
CALCULATE_DYNAMICS = 'calculate_dynamics'
MULTI_INTERFACE_DEMO_PLUGIN = 'ros2_control_demo_example_3/RRBotSystemMultiInterfaceHardware'
# The interfaces both plugins above treat as a joint's command mode.
MODE_INTERFACES = ('position', 'velocity', 'acceleration')

# One command interface of one joint: (joint, interface), ros2_control's "joint/interface".
Claim = tuple[str, str]


def interface_key(claim: Claim) -> str:
    """Return ros2_control's name of a joint's command interface: ``joint/interface``."""
    joint, interface = claim
    return f'{joint}/{interface}'


def system_claims(system: ControlSystem) -> frozenset[Claim]:
    """Return every command interface the block gives its joints."""
    return frozenset((joint.name, interface) for joint in system.joints
                     for interface in joint.command_interface_names)


def mode_switch_refusal(system: ControlSystem, start: Sequence[Claim], stop: Sequence[Claim],
                        in_use: Collection[Claim]) -> str | None:
    """Return why ``system``'s hardware refuses a switch, in one line; None if it accepts it.

    ``start`` and ``stop``: the block's command interfaces the switch starts
    and stops; ``in_use``: those the active controllers claim before it.
    """
    if not start and not stop:
        return None
    rule = _RULES.get(system.plugin)
    reason = rule(system, start, stop, in_use) if rule is not None else None
    if reason is None:
        return None
    started = ', '.join(map(interface_key, start)) or 'none'
    stopped = ', '.join(map(interface_key, stop)) or 'none'
    return (f"component '{system.name}' ({system.plugin}) did not accept command interfaces "
            f'combination (start: {started}; stop: {stopped}): {reason}')


def _mock_refusal(system: ControlSystem, start: Sequence[Claim], stop: Sequence[Claim],
                  in_use: Collection[Claim]) -> str | None:
    """mock_components/GenericSystem: one mode per started joint, with calculate_dynamics."""
    if system.hardware_params.get(CALCULATE_DYNAMICS, '').strip().lower() != 'true':
        return None
    for joint in system.joints:
        started = [interface for name, interface in start if name == joint.name]
        if not started:
            continue
        modes = [interface for interface in started if interface in MODE_INTERFACES]
        if not modes:
            return (f"Joint '{joint.name}' has to have 'position', 'velocity', or "
                    "'acceleration' interface!")
        if len(modes) > 1:
            return (f"Got multiple ({len(modes)}) starting interfaces for joint "
                    f"'{joint.name}' - this is not supported!")
    return None


def _multi_interface_demo_refusal(system: ControlSystem, start: Sequence[Claim],
                                  stop: Sequence[Claim], in_use: Collection[Claim]) -> str | None:
    """ros2_control_demos example 3: one mode on all joints at once, on joints left free."""
    joints = [joint.name for joint in system.joints]
    modes = [(joint, interface) for joint, interface in start
             if joint in joints and interface in MODE_INTERFACES]
    if len(modes) != len(joints):
        return (f"all joints ({', '.join(joints)}) must be given new command mode at the same "
                'time')
    if len({interface for _joint, interface in modes}) > 1:
        return ('all joints must have the same command mode ('
                f"{', '.join(map(interface_key, modes))})")
    stopped = {joint for joint, _interface in stop}
    busy = [joint for joint in joints
            if joint not in stopped and any(name == joint for name, _interface in in_use)]
    if busy:
        return f"joint '{busy[0]}' is still in use by an active controller"
    return None


_RULES: dict[str, Callable[[ControlSystem, Sequence[Claim], Sequence[Claim], Collection[Claim]],
                           str | None]] = {
    MOCK_PLUGIN: _mock_refusal,
    MULTI_INTERFACE_DEMO_PLUGIN: _multi_interface_demo_refusal,
}
