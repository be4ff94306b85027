"""Controller chaining, as ros2_control's controller_manager chains controllers.

A forward position group whose ``joints`` entry is ``pid/joint1`` precedes
``pid``, a chainable controller (test/support/chaining_fixtures.py) exporting the
reference interface ``pid/joint1/position``: the group writes its command
there and ``pid`` drives joint1 toward it.  The manager accepts the claim,
activates and deactivates the chain in order, refuses what would break it,
switches chained mode, and updates the group before ``pid`` every step.
"""

from __future__ import annotations

import math

import pytest
from chaining_fixtures import CHAINABLE_TYPE, GAIN, ChainableTestController, register_chainable
from ros2_control_fixtures import write_arm

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.commands.forward_command_controller import ReferenceForwarder
from pan_tilt_sim.controllers.framework import registry
from pan_tilt_sim.controllers.framework.manager import ControllerManager
from pan_tilt_sim.controllers.framework.parameter_spec import REQUIRED, STRING, Param
from pan_tilt_sim.errors import ControllerConfigError, ControllerSwitchError
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.description import load_description

PID, FORWARD, OTHER = 'pid', 'forward', 'other_forward'
GROUP = 'position_controllers/JointGroupPositionController'
VELOCITY_GROUP = 'velocity_controllers/JointGroupVelocityController'
DT = 0.001

# The controllers file of a two-controller chain; `pid` first, so that file order alone
# would update it before the group that feeds it.
CHAIN_YAML = f"""\
controller_manager:
  ros__parameters:
    {PID}: {{type: {CHAINABLE_TYPE}}}
    {FORWARD}: {{type: {GROUP}}}
    {OTHER}: {{type: {GROUP}}}
{PID}:
  ros__parameters: {{joints: [joint1]}}
{FORWARD}:
  ros__parameters: {{joints: [{PID}/joint1]}}
{OTHER}:
  ros__parameters: {{joints: [{PID}/joint1]}}
"""


@pytest.fixture(autouse=True)
def chainable(monkeypatch):
    """The test's chainable type is known to the registry."""
    return register_chainable(monkeypatch)


@pytest.fixture
def arm(tmp_path):
    """Return a function building a manager for the two-link arm from a controllers file."""
    def build(yaml=CHAIN_YAML, *, active=None, autostart=True):
        xacro = write_arm(tmp_path, yaml)
        description = load_description(xacro)
        handles = {joint.name: JointHandle(joint) for joint in description.actuated_joints}
        config = load_controllers_config(tmp_path / 'arm_controllers.yaml', {'prefix': ''})
        manager = ControllerManager(config, handles, description.model, active=active,
                                    autostart=autostart)
        return manager, handles
    return build


@pytest.fixture
def idle(arm):
    """A manager that loaded nothing (spawners will), and the arm's handles."""
    return arm(autostart=False)


def spawn(manager, *names, activate=True):
    """Load and configure ``names`` from the file, then activate them in one switch."""
    for name in names:
        spec = manager.declared[name]
        manager.load(name, spec.type, spec.params)
        manager.configure(name)
    if activate:
        manager.switch(activate=names)


def step(manager, time=0.0):
    """Run one step's updates."""
    for update in manager.updates:
        update(time, DT)


def record_lifecycle(manager, monkeypatch):
    """Record the group's reset and deactivate calls in ``pid``'s call list; return the list."""
    pid, forward = manager.controller(PID), manager.controller(FORWARD)
    for method in ('reset', 'deactivate'):
        original = getattr(forward, method)

        def recorded(original=original, method=method):
            pid.calls.append((method, FORWARD))
            original()
        monkeypatch.setattr(forward, method, recorded)
    pid.calls.clear()
    return pid.calls


# --- claims ------------------------------------------------------------------------------

def test_a_group_entry_naming_a_reference_claims_it_and_writes_the_command_through(idle):
    manager, handles = idle
    spawn(manager, PID, FORWARD)
    forward, pid = manager.controller(FORWARD), manager.controller(PID)
    assert forward.command_interfaces() == {'pid/joint1': ('position',)}
    assert manager.chain_connections(FORWARD) == {PID: ('pid/joint1/position',)}
    # Far beyond joint1's limit (pi/2): a reference is not a joint, nothing clamps it.
    forward.set_command([3.0])
    step(manager)
    assert pid.reference_interfaces()['pid/joint1/position'].value == 3.0
    assert forward.setpoints() == {'pid/joint1': 3.0}
    assert forward.actuators() == {} and forward.pids() == {}


def test_a_reference_of_a_loaded_chainable_controller_can_be_claimed_before_it_is_configured(
        idle):
    manager, _ = idle
    spec = manager.declared[PID]
    manager.load(PID, spec.type, spec.params)
    spawn(manager, FORWARD, activate=False)
    assert isinstance(manager.controller(FORWARD).members[0], ReferenceForwarder)


def test_claiming_a_reference_the_chainable_controller_does_not_export_fails_naming_it(idle):
    manager, _ = idle
    spawn(manager, PID, activate=False)
    manager.load('velocities', VELOCITY_GROUP, {'joints': ['pid/joint1']})
    with pytest.raises(ControllerConfigError) as caught:
        manager.configure('velocities')
    assert str(caught.value).endswith(
        "velocities.joints: 'pid/joint1/velocity' is not a reference interface of controller "
        "'pid' (its reference interfaces: pid/joint1/position)")


def test_claiming_a_reference_no_loaded_controller_exports_fails_naming_it(idle):
    manager, _ = idle
    spec = manager.declared[FORWARD]
    manager.load(FORWARD, spec.type, spec.params)
    with pytest.raises(ControllerConfigError) as caught:
        manager.configure(FORWARD)
    assert str(caught.value).endswith(
        "forward.joints: 'pid/joint1' is not a movable joint of the robot and "
        "'pid/joint1/position' is not a reference interface of a loaded chainable controller "
        '(movable joints: joint1, joint2; reference interfaces: none)')


def test_two_active_controllers_cannot_claim_one_reference(idle):
    manager, _ = idle
    spawn(manager, PID, FORWARD)
    spawn(manager, OTHER, activate=False)
    with pytest.raises(ControllerSwitchError, match="'forward' and 'other_forward' would both "
                                                    "claim the reference interface "
                                                    "'pid/joint1/position'"):
        manager.switch(activate=[OTHER])
    manager.switch(activate=[OTHER], deactivate=[FORWARD])
    assert manager.is_active(OTHER) and manager.controller(PID).is_chained


# --- activation and chained mode --------------------------------------------------------

def test_a_preceding_controller_cannot_be_activated_without_the_one_it_feeds(idle):
    manager, _ = idle
    spawn(manager, PID, FORWARD, activate=False)
    with pytest.raises(ControllerSwitchError) as caught:
        manager.switch(activate=[FORWARD])
    assert str(caught.value) == (
        "could not activate controller with name 'forward': The following controller with "
        "name 'pid' is currently inactive and it is not requested to be activated.")
    assert manager.active == []
    dropped = manager.switch(activate=[FORWARD], strict=False)
    assert manager.active == [] and dropped == [str(caught.value)]


def test_a_preceding_controller_cannot_be_activated_while_the_one_it_feeds_stops(idle):
    manager, _ = idle
    spawn(manager, PID)
    spawn(manager, FORWARD, activate=False)
    with pytest.raises(ControllerSwitchError, match="The following controller with name 'pid' "
                                                    'is currently active but it is requested '
                                                    'to be deactivated.'):
        manager.switch(activate=[FORWARD], deactivate=[PID])
    assert [c.name for c in manager.active] == [PID]


def test_activating_the_chain_puts_the_following_controller_in_chained_mode_first(
        idle, monkeypatch):
    manager, _ = idle
    spawn(manager, PID, FORWARD, activate=False)
    calls = record_lifecycle(manager, monkeypatch)
    assert not manager.controller(PID).is_chained
    manager.switch(activate=[FORWARD, PID])
    assert manager.controller(PID).is_chained and not manager.controller(FORWARD).is_chained
    assert calls == [('chained', PID), ('reset', PID), ('reset', FORWARD)]


def test_chained_mode_follows_whether_an_active_controller_uses_the_references(
        idle, monkeypatch):
    manager, _ = idle
    spawn(manager, PID)
    spawn(manager, FORWARD, activate=False)
    calls = record_lifecycle(manager, monkeypatch)
    # Activating the group restarts the active pid in chained mode.
    manager.switch(activate=[FORWARD])
    assert manager.controller(PID).is_chained
    assert calls == [('deactivate', PID), ('chained', PID), ('reset', PID), ('reset', FORWARD)]
    calls.clear()
    # Without it, pid runs on: restarted out of chained mode.
    manager.switch(deactivate=[FORWARD])
    assert manager.is_active(PID) and not manager.controller(PID).is_chained
    assert calls == [('deactivate', FORWARD), ('deactivate', PID), ('unchained', PID),
                     ('reset', PID)]


def test_a_following_controller_cannot_be_deactivated_while_its_preceding_one_runs(
        idle, monkeypatch):
    manager, _ = idle
    spawn(manager, PID, FORWARD)
    with pytest.raises(ControllerSwitchError) as caught:
        manager.switch(deactivate=[PID])
    assert str(caught.value) == (
        "Unable to deactivate controller with name 'pid' because preceding controller with "
        "name 'forward' is currently active and will not be deactivated.")
    assert manager.is_active(PID) and manager.controller(PID).is_chained
    assert manager.switch(deactivate=[PID], strict=False) == [str(caught.value)]
    assert manager.is_active(PID)
    calls = record_lifecycle(manager, monkeypatch)
    manager.switch(deactivate=[PID, FORWARD])  # together: preceding first
    assert manager.active == [] and not manager.controller(PID).is_chained
    assert calls == [('deactivate', FORWARD), ('deactivate', PID), ('unchained', PID)]


def test_a_chain_declared_preceding_first_starts_with_every_controller_active(arm):
    pid_line = f'    {PID}: {{type: {CHAINABLE_TYPE}}}\n'
    forward_line = f'    {FORWARD}: {{type: {GROUP}}}\n'
    yaml = CHAIN_YAML.replace(pid_line + forward_line, forward_line).replace(
        f'    {OTHER}: {{type: {GROUP}}}\n', pid_line)
    manager, _ = arm(yaml)
    assert list(manager.declared) == [FORWARD, PID]
    assert [c.name for c in manager.active] == [FORWARD, PID]
    assert manager.controller(PID).is_chained


def test_an_active_list_without_the_following_controller_is_an_error(arm):
    with pytest.raises(ControllerConfigError) as caught:
        arm(active=[FORWARD])
    assert str(caught.value) == (
        "the parameter 'active_controllers': could not activate controller with name "
        "'forward': The following controller with name 'pid' is currently inactive and it is "
        'not requested to be activated.')


def test_a_reloaded_following_controller_needs_its_preceding_one_configured_again(idle):
    manager, _ = idle
    spawn(manager, PID, FORWARD)
    manager.switch(deactivate=[PID, FORWARD])
    manager.cleanup(PID)
    manager.unload(PID)
    with pytest.raises(ControllerSwitchError, match="Unable to activate controller 'forward' "
                                                    "since the command interface "
                                                    "'pid/joint1/position' is not available."):
        manager.switch(activate=[FORWARD])
    spawn(manager, PID)  # a new pid: new references
    with pytest.raises(ControllerSwitchError, match="'pid/joint1/position' is not available"):
        manager.switch(activate=[FORWARD])
    manager.configure(FORWARD)
    manager.switch(activate=[FORWARD])
    manager.controller(FORWARD).set_command([0.2])
    step(manager)
    assert manager.controller(PID).reference_interfaces()['pid/joint1/position'].value == 0.2


def test_a_controller_of_the_following_name_that_is_not_chainable_cannot_be_fed(idle):
    manager, _ = idle
    spawn(manager, PID, FORWARD)
    manager.switch(deactivate=[PID, FORWARD])
    manager.cleanup(PID)
    manager.unload(PID)
    manager.load(PID, GROUP, {'joints': ['joint1']})
    manager.configure(PID)
    with pytest.raises(ControllerSwitchError) as caught:
        manager.switch(activate=[FORWARD, PID])
    assert str(caught.value) == (
        "could not activate controller with name 'forward': No state/reference interface from "
        "controller : 'pid/joint1/position' exist, since the following controller with name "
        "'pid' is not chainable.")


class Cascade(ChainableTestController):
    """A chainable controller that also feeds the one its ``feeds`` parameter names."""

    parameters = ChainableTestController.parameters.extend(
        Param('feeds', STRING, REQUIRED, 'The controller it feeds.'))

    @property
    def joint_names(self) -> tuple[str, ...]:
        """No joint: it commands a reference."""
        return ()

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the fed controller's ``joint1/position`` reference."""
        return {f"{self.params['feeds']}/joint1": ('position',)}

    def configure(self, joints) -> None:
        """Find the reference it feeds."""
        self.command_target(joints, f"{self.params['feeds']}/joint1", 'position', 'feeds')


def test_controllers_feeding_each_other_are_refused(idle, monkeypatch):
    manager, _ = idle
    monkeypatch.setitem(registry.CONTROLLER_TYPES, 'test/Cascade', Cascade)
    for name, feeds in (('a', 'b'), ('b', 'a')):
        manager.load(name, 'test/Cascade', {'joints': ['joint1'], 'feeds': feeds})
    manager.configure('a')
    manager.configure('b')
    with pytest.raises(ControllerSwitchError, match="the chains of 'a', 'b' loop"):
        manager.switch(activate=['a', 'b'])
    assert manager.active == []


# --- update order ------------------------------------------------------------------------

def test_the_preceding_controller_updates_first_so_a_reference_is_used_in_its_step(idle):
    manager, handles = idle
    spawn(manager, PID, FORWARD)
    assert [c.name for c in manager.active] == [FORWARD, PID]
    handles['joint1'].position = 0.1
    manager.controller(FORWARD).set_command([0.5])
    step(manager)
    assert handles['joint1'].velocity_target == pytest.approx(GAIN * (0.5 - 0.1))


def test_before_the_first_command_the_reference_is_left_alone(idle):
    manager, handles = idle
    spawn(manager, PID, FORWARD)
    step(manager)
    assert math.isnan(manager.controller(PID).reference_interfaces()['pid/joint1/position']
                      .value)
    assert handles['joint1'].velocity_target == 0.0
