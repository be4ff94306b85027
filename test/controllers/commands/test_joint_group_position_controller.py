"""position_controllers/JointGroupPositionController: a fixed-interface group.

ForwardCommandController with ``interface_name`` fixed to position.  Only what
is its own is tested here: the type, the fixed interface, its parameters and
its lifecycle.  Everything else -- commands, gains, the actuators and every
limit -- is ForwardCommandController's, and test_forward_command_controller
runs each of those tests on this type too.
"""

from controller_fixtures import loaded, raises_naming, step
from group_fixtures import GROUP_TYPES, group, make_handles

from pan_tilt_sim.controllers import CommandKind, CommandResult, create_controller
from pan_tilt_sim.controllers.commands.forward_command_controller import ForwardCommandController
from pan_tilt_sim.controllers.commands.joint_group_position_controller import (
    JointGroupPositionController,
)
from pan_tilt_sim.controllers.framework.manager import ACTIVE, INACTIVE, UNCONFIGURED

TYPE = GROUP_TYPES['position']


def test_is_a_forward_command_controller_on_the_position_interface_of_every_joint():
    controller = group(TYPE)
    assert isinstance(controller, JointGroupPositionController)
    assert isinstance(controller, ForwardCommandController)
    assert controller.command_topic == 'commands'
    assert controller.command_kind is CommandKind.FLOAT64_ARRAY
    assert controller.interface_name == 'position'
    assert controller.command_interfaces() == {'shoulder': ('position',), 'slide': ('position',)}


def test_joint_group_types_fix_their_interface():
    assert group(TYPE, interface_name='effort').interface_name == 'position'


def test_a_missing_joints_list_is_a_configuration_error():
    with raises_naming('grp.joints'):
        create_controller('grp', TYPE, {}, 'test.yaml')


def test_the_manager_activates_it_to_drive_each_joints_setpoint_and_cleans_it_up():
    handles = make_handles()
    manager = loaded('grp', TYPE, {'joints': ['shoulder', 'slide']}, handles)
    assert manager.state('grp') == UNCONFIGURED
    controller = manager.configure('grp')
    assert manager.state('grp') == INACTIVE
    handles['shoulder'].position, handles['slide'].position = 0.3, 0.2
    manager.switch(activate=['grp'])
    assert manager.state('grp') == ACTIVE
    assert controller.setpoints() == {'shoulder': 0.3, 'slide': 0.2}  # held where they are
    assert controller.set_command([0.4, 0.1]) is CommandResult.ACCEPTED
    step(manager, 1000)
    assert controller.setpoints() == {'shoulder': 0.4, 'slide': 0.1}
    last = [handle.velocity_target for handle in handles.values()]
    assert last[0] > 0.0 > last[1]  # the joints, still at 0.3 and 0.2, are driven there
    manager.switch(deactivate=['grp'])
    controller.set_command([0.0, 0.0])
    step(manager, 10, start=1000)
    assert [handle.velocity_target for handle in handles.values()] == last
    manager.cleanup('grp')
    assert manager.state('grp') == UNCONFIGURED
