"""effort_controllers/JointGroupEffortController: a fixed-interface group.

ForwardCommandController with ``interface_name`` fixed to effort.  Only what
is its own is tested here: the type, the fixed interface, its parameters and
its lifecycle.  Everything else -- commands, gains, the actuators and every
limit -- is ForwardCommandController's, and test_forward_command_controller
runs each of those tests on this type too.
"""

from controller_fixtures import loaded, raises_naming, step
from group_fixtures import GROUP_TYPES, group, make_handles

from pan_tilt_sim.controllers import CommandKind, CommandResult, create_controller
from pan_tilt_sim.controllers.commands.forward_command_controller import ForwardCommandController
from pan_tilt_sim.controllers.commands.joint_group_effort_controller import (
    JointGroupEffortController,
)
from pan_tilt_sim.controllers.framework.manager import ACTIVE, INACTIVE, UNCONFIGURED

TYPE = GROUP_TYPES['effort']


def test_is_a_forward_command_controller_on_the_effort_interface_of_every_joint():
    controller = group(TYPE)
    assert isinstance(controller, JointGroupEffortController)
    assert isinstance(controller, ForwardCommandController)
    assert controller.command_topic == 'commands'
    assert controller.command_kind is CommandKind.FLOAT64_ARRAY
    assert controller.interface_name == 'effort'
    assert controller.command_interfaces() == {'shoulder': ('effort',), 'slide': ('effort',)}


def test_joint_group_types_fix_their_interface():
    assert group(TYPE, interface_name='position').interface_name == 'effort'


def test_a_missing_joints_list_is_a_configuration_error():
    with raises_naming('grp.joints'):
        create_controller('grp', TYPE, {}, 'test.yaml')


def test_the_manager_activates_it_to_drive_each_joints_effort_and_cleans_it_up():
    handles = make_handles()
    manager = loaded('grp', TYPE, {'joints': ['shoulder', 'slide']}, handles)
    assert manager.state('grp') == UNCONFIGURED
    controller = manager.configure('grp')
    assert manager.state('grp') == INACTIVE
    controller.set_command([5.0, 5.0])
    manager.switch(activate=['grp'])  # activation starts it afresh: no effort
    assert manager.state('grp') == ACTIVE
    step(manager, 1)
    assert [handle.effort for handle in handles.values()] == [0.0, 0.0, 0.0]
    assert controller.set_command([-4.0, 12.0]) is CommandResult.ACCEPTED
    step(manager, 1, start=1)
    assert controller.setpoints() == {'shoulder': -4.0, 'slide': 12.0}
    assert [handle.effort for handle in handles.values()] == [-4.0, 12.0, 0.0]
    manager.switch(deactivate=['grp'])
    controller.set_command([0.0, 0.0])
    step(manager, 10, start=2)
    assert [handle.effort for handle in handles.values()] == [-4.0, 12.0, 0.0]
    manager.cleanup('grp')
    assert manager.state('grp') == UNCONFIGURED
