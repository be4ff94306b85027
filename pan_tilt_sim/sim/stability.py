"""Start-up checks: can PyBullet integrate the robot at all, and is each PID stable.

**The robot.**  The parser refuses what is known to break PyBullet
(:mod:`pan_tilt_sim.model.urdf`); what is left -- a joint origin so far out
that its square overflows, say -- shows in the first steps.  Before the
simulation starts, :func:`check_startup_stability` steps the robot
:data:`STARTUP_TRIAL_STEPS` times with no effort applied and puts it back as
it was; a joint whose position or velocity is then not finite ends start-up
with a :class:`~pan_tilt_sim.errors.DescriptionError` naming the joint and
the likely cause: the number of the description farthest from 1 in
magnitude, where overflow and underflow come from.  An object to spawn gets
the same trial, alone in a PyBullet client of its own, before it enters the
world (:class:`ObjectTrials`).

**The gains.**

Design notes: docs/design/sim.md#stabilitypy.
"""

from __future__ import annotations

import math
import pathlib
from collections.abc import Mapping, Sequence

from pan_tilt_sim.controllers.framework.base import ActuatorKind, Drive, JointHandle
from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.robot import JointKind, RobotModel
from pan_tilt_sim.sim.bullet import pybullet, quiet_native_output
from pan_tilt_sim.sim.physics import STANDARD_GRAVITY, STATE_POSITION, STATE_VELOCITY, Physics

# Steps of the start-up trial (a robot's, an object's): a description PyBullet cannot
# integrate gives non-finite states within the first few.
STARTUP_TRIAL_STEPS = 200


def check_startup_stability(physics: Physics, description: RobotDescription) -> None:
    """Refuse a robot whose joint states are not finite within the first steps without effort.

    Raises :class:`DescriptionError` naming the joint and the likely cause;
    the simulation is left as it was either way (:meth:`Physics.trial`).
    """
    outcome = physics.trial(STARTUP_TRIAL_STEPS)
    if outcome is None:
        return
    steps, states = outcome
    broken = [joint.name for joint, state in zip(physics.joints, states, strict=True)
              if not (math.isfinite(state[STATE_POSITION])
                      and math.isfinite(state[STATE_VELOCITY]))]
    model = description.model
    cause, owner = most_extreme_number(model)
    order = [joint.name for joint in model.tree_joints if joint.name in broken]
    joint = owner if owner in broken else (order or broken)[0]
    raise DescriptionError(
        f"{description.source}: joint '{joint}' has a non-finite position or velocity after "
        f'{_steps(steps)} with no effort applied: PyBullet cannot integrate this '
        f'robot{_likely(cause)}')


class ObjectTrials:
    """Objects tried one after the other in one PyBullet client of their own.

    :meth:`run` loads the object ``fixed`` to the world or free, with the
    URDF's inertia, under gravity, and steps it :data:`STARTUP_TRIAL_STEPS`
    times with its joints passive, then removes it.  A fixed object without
    joints cannot move, so it is not stepped.  Connecting a client costs more
    than a small object's trial, so the client is made once, on the first
    trial, and kept until :meth:`close`.  One thread at a time.
    """

    def __init__(self, time_step: float) -> None:
        self._time_step = time_step
        self._client: int | None = None

    def run(self, path: pathlib.Path, fixed: bool, model: RobotModel) -> str:
        """Return what went non-finite ('' if nothing did, or PyBullet cannot load it).

        A URDF PyBullet cannot load is not this method's business: the answer
        is '' and loading it for real says why.
        """
        if fixed and not any(joint.kind.is_actuated for joint in model.joints):
            return ''
        client = self._connect()
        try:
            with quiet_native_output():
                body = pybullet.loadURDF(str(path), useFixedBase=fixed,
                                         flags=pybullet.URDF_USE_INERTIA_FROM_FILE,
                                         physicsClientId=client)
        except pybullet.error:
            return ''
        try:
            return self._steps_finite(client, body, model)
        finally:
            pybullet.removeBody(body, physicsClientId=client)

    def close(self) -> None:
        """Disconnect the trial client (idempotent)."""
        if self._client is not None:
            pybullet.disconnect(physicsClientId=self._client)
            self._client = None

    def _connect(self) -> int:
        if self._client is None:
            with quiet_native_output():
                client = pybullet.connect(pybullet.DIRECT)
            pybullet.setGravity(0.0, 0.0, -STANDARD_GRAVITY, physicsClientId=client)
            pybullet.setTimeStep(self._time_step, physicsClientId=client)
            self._client = client
        return self._client

    @staticmethod
    def _steps_finite(client: int, body: int, model: RobotModel) -> str:
        joints = list(range(pybullet.getNumJoints(body, physicsClientId=client)))
        if joints:  # passive: PyBullet's default motors off
            pybullet.setJointMotorControlArray(body, joints, pybullet.VELOCITY_CONTROL,
                                               forces=[0.0] * len(joints),
                                               physicsClientId=client)
        names = [pybullet.getJointInfo(body, index, physicsClientId=client)[1].decode('utf-8')
                 for index in joints]
        for count in range(1, STARTUP_TRIAL_STEPS + 1):
            pybullet.stepSimulation(physicsClientId=client)
            position, orientation = pybullet.getBasePositionAndOrientation(
                body, physicsClientId=client)
            what = '' if all(math.isfinite(v) for v in (*position, *orientation)) else \
                'its base pose'
            if not what and joints:
                states = pybullet.getJointStates(body, joints, physicsClientId=client)
                what = next((f"joint '{name}'" for name, state in zip(names, states, strict=True)
                             if not (math.isfinite(state[STATE_POSITION])
                                     and math.isfinite(state[STATE_VELOCITY]))), '')
            if what:
                cause, _joint = most_extreme_number(model)
                return (f'{what} is not finite after {_steps(count)} alone, with no effort '
                        f'applied: PyBullet cannot integrate this object{_likely(cause)}')
        return ''


def _steps(count: int) -> str:
    return f"{count} physics step{'s' if count > 1 else ''}"


def _likely(cause: str) -> str:
    return f'; likely cause: {cause}, the most extreme number of the description' if cause else ''


def most_extreme_number(model: RobotModel) -> tuple[str, str]:
    """Return the description's number farthest from 1 in magnitude, and the joint it moves.

    The number as ``<element> value`` with its owner; the joint is the
    nearest movable joint at or above it ('' if there is none).
    """
    parent_joint = {joint.child: joint for joint in model.joints}

    def movable_at_or_above(joint_name: str) -> str:
        joint = model.joint(joint_name)
        while not joint.kind.is_actuated:
            above = parent_joint.get(joint.parent)
            if above is None:
                return ''
            joint = above
        return joint.name

    candidates = []  # (where, value, joint)
    for link in model.links:
        inertial = link.inertial
        above = parent_joint.get(link.name)
        joint = movable_at_or_above(above.name) if above is not None else ''
        if inertial is None:
            continue
        owner = f"link '{link.name}'"
        candidates.append((f'{owner} <mass>', inertial.mass, joint))
        candidates += [(f'{owner} <inertia {field}>', getattr(inertial, field), joint)
                       for field in ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz')]
        candidates += [(f'{owner} <inertial><origin xyz>', value, joint)
                       for value in inertial.origin.translation]
    for spec in model.joints:
        owner, joint = f"joint '{spec.name}'", movable_at_or_above(spec.name)
        candidates += [(f'{owner} <origin xyz>', value, joint)
                       for value in spec.origin.translation]
        candidates += [(f'{owner} <{element}>', getattr(spec, field), joint) for element, field in (
            ('limit lower', 'lower'), ('limit upper', 'upper'), ('limit effort', 'effort_limit'),
            ('limit velocity', 'velocity_limit'), ('dynamics damping', 'damping'),
            ('dynamics friction', 'friction'))]
        if spec.mimic is not None:
            candidates += [(f'{owner} <mimic multiplier>', spec.mimic.multiplier, joint),
                           (f'{owner} <mimic offset>', spec.mimic.offset, joint)]
    scored = [(abs(math.log10(abs(value))), where, value, joint)
              for where, value, joint in candidates if value != 0.0 and math.isfinite(value)]
    if not scored:
        return '', ''
    _, where, value, joint = max(scored, key=lambda item: item[0])
    return f'{where} {value:g}', joint


def largest_stable_time_step(p: float, d: float, inertia: float) -> float:
    """Return the time step below which ``d dt / 2 + p dt^2 / 4 < inertia``."""
    if p > 0.0:
        return (-d / 2.0 + math.sqrt(d * d / 4.0 + p * inertia)) / (p / 2.0)
    return math.inf if d <= 0.0 else 2.0 * inertia / d


def pid_stability_warnings(physics: Physics, handles: Sequence[JointHandle],
                           time_step: float,
                           periods: Mapping[str, float] | None = None) -> list[str]:
    """Return one warning per PID-driven joint whose gains are unstable at its controller's period.

    ``periods``: each controller's update period (s) by name, a whole number
    of ``time_step`` s; a controller not named updates every step.
    """
    # A PID whose output is not an effort (a velocity target, say) is no explicit effort loop.
    checked = [handle for handle in handles
               if handle.actuator.pid is not None and handle.drive is Drive.EFFORT]
    if not checked:
        return []
    inertias = dict(zip((joint.name for joint in physics.joints), physics.smallest_inertias(),
                        strict=True))
    warnings = []
    for handle in checked:
        actuator = handle.actuator
        gains = actuator.pid.gains
        inertia = inertias[handle.name]
        unit = 'kg' if handle.spec.kind is JointKind.PRISMATIC else 'kg*m^2'
        where = f"joint '{handle.name}' ({actuator.controller})"
        dt = (periods or {}).get(actuator.controller, time_step)
        steps = max(1, round(dt / time_step))
        if steps > 1:
            warning = _held_effort_warning(where, actuator.kind, gains.p, gains.d, inertia,
                                           unit, dt, steps)
            if warning is not None:
                warnings.append(warning)
            continue
        if actuator.kind is ActuatorKind.VELOCITY_PID:
            if gains.p * dt / 2.0 < inertia:
                continue
            warnings.append(
                f'{where}: velocity PID p {gains.p:g} is unstable at time_step {dt:g} s for '
                f'its effective inertia {inertia:.3g} {unit} (needs p * time_step / 2 < '
                f'inertia): use p < {2.0 * inertia / dt:.3g}, a time_step below '
                f'{2.0 * inertia / gains.p:.3g} s, or no gains (the ideal actuator)')
            continue
        need = gains.d * dt / 2.0 + gains.p * dt * dt / 4.0
        if need < inertia:
            continue
        largest_d = (4.0 * inertia - gains.p * dt * dt) / (2.0 * dt)
        advice = (f'use d < {largest_d:.3g}' if largest_d > 0.0 else
                  f'use p < {4.0 * inertia / (dt * dt):.3g} and a smaller d')
        warnings.append(
            f'{where}: PID p {gains.p:g} d {gains.d:g} is unstable at time_step {dt:g} s for '
            f'its effective inertia {inertia:.3g} {unit} (needs d * time_step / 2 + '
            f'p * time_step^2 / 4 = {need:.3g} < inertia): {advice}, a time_step below '
            f'{largest_stable_time_step(gains.p, gains.d, inertia):.3g} s, or no gains '
            '(the ideal actuator)')
    return warnings


def _held_effort_warning(where: str, kind: ActuatorKind, p: float, d: float, inertia: float,
                         unit: str, period: float, steps: int) -> str | None:
    """Say why a PID updated every ``steps`` physics steps (``period`` s) is unstable, or None.

    The rules of the module's description for an effort held ``steps`` steps.
    """
    at = (f'at its update period {period:g} s ({steps} physics steps, the effort held in '
          'between)')
    if kind is ActuatorKind.VELOCITY_PID:
        if p * period / 2.0 < inertia:
            return None
        return (f'{where}: velocity PID p {p:g} is unstable {at} for its effective inertia '
                f'{inertia:.3g} {unit} (needs p * period / 2 < inertia): use p < '
                f'{2.0 * inertia / period:.3g}, a higher update_rate, or no gains '
                '(the ideal actuator)')
    need = d * period / 2.0 + p * period * period / (4.0 * steps)
    least_d = p * period * (steps - 1) / (2.0 * steps)
    if need < inertia and d > least_d:
        return None
    return (f'{where}: PID p {p:g} d {d:g} is unstable {at} for its effective inertia '
            f'{inertia:.3g} {unit} (needs d * period / 2 + p * period^2 / (4 n) = '
            f'{need:.3g} < inertia and d > p * period * (n - 1) / (2 n) = '
            f'{least_d:.3g}, n = {steps}): a higher update_rate, other gains, or no gains '
            '(the ideal actuator)')
