"""The ROS ``controller_manager`` node: services over the pure controllers.framework.manager.

A ``controller_manager`` node in sim_node's process, so ros2_control's spawner works unchanged.

ros2_control's ``spawner`` and ``unspawner`` (jazzy) talk to a node called
``controller_manager`` in the robot's namespace (``/controller_manager``, or
``<ns>/controller_manager``): they set the controller's ``<name>.type`` and
``<name>.params_file`` (and ``.fallback_controllers``) through its parameter
services, then call ``load_controller``, ``configure_controller`` and
``switch_controller`` (STRICT), and treat ``ok == false`` as failure.
:class:`ControllerManagerNode` offers every service of
``controller_manager_msgs`` (older spawners wait until all of them exist on
that node) and answers them with ros2_control's rules (see the design notes).

Design notes: docs/design/ros.md#controller_managerpy.
"""

from __future__ import annotations

import pathlib
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from lifecycle_msgs.msg import State
from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.context import Context
from rclpy.node import Node
from rclpy.parameter import Parameter

from pan_tilt_sim.controllers import CommandController
from pan_tilt_sim.controllers.broadcasters.joint_state_broadcaster import JointStateBroadcaster
from pan_tilt_sim.controllers.framework.manager import ACTIVE, INACTIVE, ControllerManager
from pan_tilt_sim.controllers.framework.registry import CONTROLLER_TYPES, supported_types
from pan_tilt_sim.errors import ConfigurationError, ControllerConfigError, ControllerSwitchError
from pan_tilt_sim.model.controller_config import (
    DEFAULT_UPDATE_RATE,
    TYPE_FIELD,
    UPDATE_RATE_FIELD,
    merge_parameters,
    node_parameters,
    unflatten,
)
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.ros_arguments import RosArguments, node_rules, parse_ros_arguments
from pan_tilt_sim.ros.controller_bindings import ControllerBindings

NODE_NAME = 'controller_manager'
PARAMS_FILE = 'params_file'
FALLBACK = 'fallback_controllers'
NODE_OPTIONS_ARGS = 'node_options_args'
INITIAL_STATE_PARAMETER = 'hardware_components_initial_state'
INITIAL_STATES = ('unconfigured', 'inactive')
# What a spawner sets on the controller_manager, per controller: ``<controller>.<field>``.
CONTROLLER_FIELDS = (TYPE_FIELD, PARAMS_FILE, FALLBACK, NODE_OPTIONS_ARGS)
STRICTNESS_PARAMETER = 'defaults.switch_controller.strictness'
BEST_EFFORT, STRICT = 1, 2  # controller_manager_msgs/srv/SwitchController
BASE_CLASS = 'controller_interface::ControllerInterface'
CHAINABLE_BASE_CLASS = 'controller_interface::ChainableControllerInterface'
DATA_TYPE = 'double'
ALL_INTERFACES = ('position', 'velocity', 'effort')
ACTIVE_STATE = State(id=State.PRIMARY_STATE_ACTIVE, label='active')
COMPONENT_TYPE = 'system'
NOTHING_TO_SWITCH = ('After checking the controllers, no controllers need to be activated or '
                     'deactivated.')


class ControllerManagerServices:
    """ros2_control's controller_manager services and parameters, on ``node``.

    ``node`` is the controller_manager: a node of its own beside sim_node
    (:class:`ControllerManagerNode`), or sim_node itself when it runs under
    that name in ros2_control_node's place.  ``update_rate`` (Hz) is the
    controller_manager's own (default: the controllers file's, else 100);
    ``shared_parameters(name)`` is what the controller_manager's own
    arguments give controller ``name``'s node besides its own (ros2_control
    passes them on to every controller node), read at load.
    """

    def __init__(self, node: Node, bindings: ControllerBindings, manager: ControllerManager,
                 model: RobotModel, *, substitutions: Mapping[str, str] | None = None,
                 source: str = '', update_rate: int | None = None,
                 shared_parameters: Callable[[str], Mapping[str, Any]] | None = None) -> None:
        from controller_manager_msgs import srv

        self._node = node
        self._bindings = bindings
        self._manager = manager
        self._shared_parameters = shared_parameters
        self._model = model
        self._substitutions = dict(substitutions or {})
        self._source = source
        rate = update_rate or manager.update_rate or DEFAULT_UPDATE_RATE
        self.update_rate = int(round(rate))
        if not node.has_parameter(UPDATE_RATE_FIELD):
            node.declare_parameter(UPDATE_RATE_FIELD, self.update_rate, ParameterDescriptor(
                description='Hz at which controllers update (the controllers file says).',
                read_only=True))
        if not node.has_parameter(STRICTNESS_PARAMETER):
            node.declare_parameter(STRICTNESS_PARAMETER, 'best_effort', ParameterDescriptor(
                description='switch_controller strictness 0 means this: strict or best_effort.'))
        for name, spec in manager.declared.items():
            if isinstance(spec.type, str) and not node.has_parameter(f'{name}.{TYPE_FIELD}'):
                node.declare_parameter(f'{name}.{TYPE_FIELD}', spec.type)
        node.add_on_set_parameters_callback(self._check_parameters)
        self._report_initial_states()
        services = [
            (srv.ListControllers, 'list_controllers', self._list),
            (srv.ListControllerTypes, 'list_controller_types', self._list_types),
            (srv.ListHardwareComponents, 'list_hardware_components', self._list_components),
            (srv.ListHardwareInterfaces, 'list_hardware_interfaces', self._list_interfaces),
            (srv.LoadController, 'load_controller', self._load),
            (srv.ConfigureController, 'configure_controller', self._configure),
            (srv.CleanupController, 'cleanup_controller', self._cleanup),
            (srv.UnloadController, 'unload_controller', self._unload),
            (srv.SwitchController, 'switch_controller', self._switch),
            (srv.ReloadControllerLibraries, 'reload_controller_libraries', self._reload),
            (srv.SetHardwareComponentState, 'set_hardware_component_state',
             self._set_component_state),
        ]
        self._cm_services = [node.create_service(service_type, f'~/{name}', callback)
                             for service_type, name, callback in services]
        from controller_manager_msgs.msg import (
            ChainConnection,
            ControllerState,
            HardwareComponentState,
            HardwareInterface,
        )

        self._chain_connection = ChainConnection
        self._controller_state = ControllerState
        self._component_state = HardwareComponentState
        self._interface = HardwareInterface

    def _report_initial_states(self) -> None:
        """Read ``hardware_components_initial_state``: say what each name it lists becomes.

        The simulated hardware is one always-active component per
        ``<ros2_control>`` block (there is nothing to configure), so a
        component listed as ``unconfigured`` or ``inactive`` starts active,
        with an info line saying so; an unknown name gets upstream's warning.
        """
        node = self._node
        known = {name for name, _plugin, _joints in self._components()}
        for state in INITIAL_STATES:
            parameter = f'{INITIAL_STATE_PARAMETER}.{state}'
            if not node.has_parameter(parameter):
                node.declare_parameter(parameter, None, ParameterDescriptor(
                    description=f'Hardware components to leave {state} at start-up (the '
                    'simulated hardware is always active).', dynamic_typing=True))
            names = self._parameter(parameter) or []
            for name in [names] if isinstance(names, str) else names:
                if name not in known:
                    node.get_logger().warning(
                        f"Hardware component '{name}' is unknown, therefore not set in "
                        f"'{state}' state.")
                else:
                    node.get_logger().info(
                        f"hardware component '{name}' starts active, not {state} "
                        f"('{parameter}'): the simulated hardware has no {state} state")

    # --- parameters the spawner sets -----------------------------------------------------------

    def _check_parameters(self, changed: Sequence[Parameter]) -> SetParametersResult:
        """``<name>.type`` must be a string, ``.params_file`` a string or string list, ...."""
        for parameter in changed:
            name, _, field = parameter.name.rpartition('.')
            value = parameter.value
            if not name or value is None:  # None: declared, not set yet
                continue
            if field == TYPE_FIELD and not isinstance(value, str):
                return SetParametersResult(
                    successful=False, reason=f"'{parameter.name}' must be a string")
            if field == PARAMS_FILE and not _is_string_or_strings(value):
                return SetParametersResult(
                    successful=False,
                    reason=f"'{parameter.name}' must be a file name or a list of them")
            if field == NODE_OPTIONS_ARGS and not _is_string_or_strings(value):
                return SetParametersResult(
                    successful=False,
                    reason=f"'{parameter.name}' must be a list of ROS arguments")
            if field == FALLBACK and not _is_strings(value):
                return SetParametersResult(
                    successful=False,
                    reason=f"'{parameter.name}' must be a list of controller names")
        return SetParametersResult(successful=True)

    def _parameter(self, name: str) -> Any:
        if not self._node.has_parameter(name):
            return None
        parameter = self._node.get_parameter(name)
        return None if parameter.type_ == Parameter.Type.NOT_SET else parameter.value

    def _node_arguments(self, name: str) -> RosArguments:
        """Return the controller node's own arguments, ``<name>.node_options_args``.

        The spawner's ``--controller-ros-args``: remaps, ``-p`` and
        ``--params-file`` count; renaming or moving the node is refused.
        """
        field = f"'{name}.{NODE_OPTIONS_ARGS}'"
        value = self._parameter(f'{name}.{NODE_OPTIONS_ARGS}') or []
        items = value.split() if isinstance(value, str) else list(value)
        arguments = parse_ros_arguments(items, field, whole=True)
        moved = node_rules(arguments, name)
        if moved:
            raise ControllerConfigError(
                f"{field}: {', '.join(moved)}: a controller's node is not renamed or moved "
                "here; remap its topics instead (-r ~/name:=/other)")
        return arguments

    def _controller_parameters(self, name: str, spec: Any, files: Sequence[str],
                               arguments: RosArguments) -> dict[str, Any]:
        """Return the parameters controller ``name`` loads with, in the order rcl reads them.

        The controllers file's section for it (or the controller_manager's
        update_rate and what its own arguments give the controller), then
        ``<name>.params_file``, then the controller node's own arguments:
        later ones win, name by name.
        """
        if spec is not None:
            params: dict[str, Any] = dict(spec.params)
        else:
            params = {UPDATE_RATE_FIELD: float(self.update_rate)}
            if self._shared_parameters is not None:
                merge_parameters(params, self._shared_parameters(name))
        own = [pathlib.Path(file) for file in files] + list(arguments.params_files)
        if own:
            merge_parameters(params, node_parameters(own, name, self._substitutions,
                                                     args_name="sim_node's 'controllers_args'"))
        merge_parameters(params, unflatten(arguments.parameters_for(name)))
        return params

    # --- load / configure / cleanup / unload ---------------------------------------------------

    def _load(self, request, response):
        response.ok = False
        name = request.name
        if self._manager.is_loaded(name):
            self._node.get_logger().error(
                f"A controller named '{name}' was already loaded inside the controller manager")
            return response
        type_name = self._parameter(f'{name}.{TYPE_FIELD}')
        if not type_name:
            self._node.get_logger().error(
                f"The 'type' param was not defined for '{name}' (set '{name}.{TYPE_FIELD}', "
                "as the spawner's --param-file does from the file's 'type')")
            return response
        fallbacks = self._parameter(f'{name}.{FALLBACK}') or []
        if name in fallbacks:
            self._node.get_logger().error(
                f"Controller '{name}' cannot be a fallback controller of itself")
            return response
        files = self._parameter(f'{name}.{PARAMS_FILE}') or []
        files = [files] if isinstance(files, str) else list(files)
        spec = self._manager.declared.get(name)
        source = ' + '.join(files) or self._source
        try:
            arguments = self._node_arguments(name)
            params = self._controller_parameters(name, spec, files, arguments)
            params[TYPE_FIELD] = type_name
            self._bindings.load(name, type_name, params, source, arguments)
        except ConfigurationError as err:
            self._node.get_logger().error(f"Failed to load controller '{name}': {err}")
            return response
        remaps = ', '.join(f'{rule.source}:={rule.target}' for rule in arguments.remaps)
        self._node.get_logger().info(f"Loaded controller '{name}' ({type_name})"
                                     + (f', remapping {remaps}' if remaps else ''))
        response.ok = True
        return response

    def _configure(self, request, response):
        response.ok = self._lifecycle('configure', request.name, self._bindings.configure)
        return response

    def _cleanup(self, request, response):
        response.ok = self._lifecycle('cleanup', request.name, self._bindings.cleanup)
        return response

    def _unload(self, request, response):
        response.ok = self._lifecycle('unload', request.name, self._bindings.unload)
        return response

    def _lifecycle(self, action: str, name: str, change) -> bool:
        try:
            change(name)
        except ConfigurationError as err:
            self._node.get_logger().error(f"Failed to {action} controller '{name}': {err}")
            return False
        done = {'configure': 'Configured', 'cleanup': 'Cleaned up', 'unload': 'Unloaded'}
        self._node.get_logger().info(f"{done[action]} controller '{name}'")
        return True

    # --- switch --------------------------------------------------------------------------------

    def _switch(self, request, response):
        strictness = request.strictness
        if strictness == 0:
            default = str(self._parameter(STRICTNESS_PARAMETER) or '').lower()
            strictness = STRICT if default == 'strict' else BEST_EFFORT
        strict = strictness == STRICT
        activate = list(request.activate_controllers)
        deactivate = list(request.deactivate_controllers)
        before = {c.name for c in self._manager.active}
        try:
            dropped = self._bindings.switch(activate, deactivate, strict=strict)
        except ControllerSwitchError as err:
            response.ok, response.message = False, str(err)
            self._node.get_logger().error(f'switch_controller refused: {err}')
            return response
        for problem in dropped:
            self._node.get_logger().warning(f'switch_controller (BEST_EFFORT): {problem}')
        after = {c.name for c in self._manager.active}
        response.ok = True
        if before == after and not (set(activate) & set(deactivate) & after):
            response.message = NOTHING_TO_SWITCH
        else:
            changes = [f'activated {", ".join(sorted(after - before))}' if after - before else '',
                       f'deactivated {", ".join(sorted(before - after))}'
                       if before - after else '']
            self._node.get_logger().info('switch_controller: ' + '; '.join(filter(None, changes)))
        return response

    # --- lists ---------------------------------------------------------------------------------

    def _list(self, request, response):
        manager = self._manager
        states = []
        for controller in manager.controllers:
            state = manager.state(controller.name)
            configured = state in (INACTIVE, ACTIVE)
            commands = _flatten(controller.command_interfaces())
            # Its own update_rate, else the controller_manager's (a ROS 1 file's controllers
            # give none: they update every physics step, and are shown at the manager's rate).
            rate = manager.update_rate_of(controller.name) or self.update_rate
            # As upstream: the chain of a controller that is inactive or active, the
            # interfaces named without their controller's prefix.
            references = [_without_prefix(name) for name in controller.reference_interfaces()]
            connections = [
                self._chain_connection(name=following,
                                       reference_interfaces=[_without_prefix(name)
                                                             for name in claimed])
                for following, claimed in sorted(manager.chain_connections(
                    controller.name).items())]
            states.append(self._controller_state(
                name=controller.name, state=state, type=controller.type_name, is_async=False,
                update_rate=int(round(rate)) if isinstance(rate, int | float) else
                self.update_rate,
                claimed_interfaces=commands if state == ACTIVE else [],
                required_command_interfaces=commands if configured else [],
                required_state_interfaces=self._state_interfaces_of(controller)
                if configured else [],
                is_chainable=controller.chainable, is_chained=controller.is_chained,
                reference_interfaces=references if configured else [],
                chain_connections=connections if configured else []))
        response.controller = states
        return response

    def _list_types(self, request, response):
        response.types = supported_types()
        response.base_classes = [CHAINABLE_BASE_CLASS if CONTROLLER_TYPES[name].chainable
                                 else BASE_CLASS for name in response.types]
        return response

    def _list_interfaces(self, request, response):
        claimed = {name for controller in self._manager.active
                   for name in _flatten(controller.command_interfaces())}
        response.command_interfaces = [
            self._interface(name=name, data_type=DATA_TYPE, is_available=True,
                            is_claimed=name in claimed)
            for name in self._command_interface_names()]
        response.state_interfaces = [
            self._interface(name=name, data_type=DATA_TYPE, is_available=True, is_claimed=False)
            for name in self._state_interface_names()]
        return response

    def _list_components(self, request, response):
        components = []
        for name, plugin, joints in self._components():
            joint_set = set(joints)
            claimed = {item for controller in self._manager.active
                       for item in _flatten(controller.command_interfaces())}
            components.append(self._component_state(
                name=name, type=COMPONENT_TYPE, is_async=False, rw_rate=self.update_rate,
                class_type=plugin, plugin_name=plugin, state=ACTIVE_STATE,
                command_interfaces=[
                    self._interface(name=item, data_type=DATA_TYPE, is_available=True,
                                    is_claimed=item in claimed)
                    for item in self._command_interface_names()
                    if item.rpartition('/')[0] in joint_set],
                state_interfaces=[
                    self._interface(name=item, data_type=DATA_TYPE, is_available=True,
                                    is_claimed=False)
                    for item in self._state_interface_names()
                    if item.rpartition('/')[0] in joint_set]))
        response.component = components
        return response

    def _set_component_state(self, request, response):
        names = [name for name, _plugin, _joints in self._components()]
        response.state = ACTIVE_STATE
        if request.name not in names:
            self._node.get_logger().error(
                f"hardware component '{request.name}' does not exist (components: "
                f"{', '.join(names)})")
            response.ok = False
            return response
        response.ok = request.target_state.id == State.PRIMARY_STATE_ACTIVE or (
            request.target_state.label == 'active')
        if not response.ok:
            self._node.get_logger().warning(
                f"hardware component '{request.name}' is the simulation: it stays active")
        return response

    def _reload(self, request, response):
        manager = self._manager
        loaded = [c.name for c in manager.controllers]
        if loaded and not request.force_kill:
            self._node.get_logger().error(
                f'cannot reload controller libraries: controllers are loaded '
                f"({', '.join(loaded)}); unload them or ask with force_kill")
            response.ok = False
            return response
        try:
            self._bindings.switch([], [c.name for c in manager.active], strict=False)
            for name in loaded:
                self._bindings.unload(name)
        except ConfigurationError as err:
            self._node.get_logger().error(f'reload_controller_libraries: {err}')
            response.ok = False
            return response
        response.ok = True
        return response

    # --- the joints' interfaces ----------------------------------------------------------------

    def _components(self) -> list[tuple[str, str, list[str]]]:
        """(name, plugin, joints, sensors and gpios) per <ros2_control> block.

        One more for the robot's joints outside every block (or all of them).
        """
        actuated = [joint.name for joint in self._model.actuated_joints]
        systems = [(system.name, system.plugin,
                    [j.name for j in (*system.joints, *system.sensors, *system.gpios)])
                   for system in self._model.ros2_control]
        listed = {joint for _name, _plugin, joints in systems for joint in joints}
        rest = [joint for joint in actuated if joint not in listed]
        if rest or not systems:
            systems.append((self._model.name, 'pan_tilt_sim/PyBulletSystem', rest))
        return systems

    def _interfaces_of(self, joint: str, commands: bool) -> tuple[str, ...]:
        control = self._model.control_joint(joint)
        if control is None:
            return ALL_INTERFACES
        return control.command_interface_names if commands else control.state_interface_names

    def _command_interface_names(self) -> list[str]:
        joints = [f'{joint.name}/{interface}' for joint in self._model.actuated_joints
                  if joint.mimic is None for interface in self._interfaces_of(joint.name, True)]
        return joints + list(self._manager.hardware.command_interfaces)

    def _state_interface_names(self) -> list[str]:
        joints = [f'{joint.name}/{interface}' for joint in self._model.actuated_joints
                  for interface in self._interfaces_of(joint.name, False)]
        return joints + list(self._manager.hardware.state_interfaces)

    def _state_interfaces_of(self, controller) -> list[str]:
        if isinstance(controller, JointStateBroadcaster):
            # What it reads that the hardware lists (it reads every measured interface).
            return [f'{joint}/{interface}'
                    for joint, read in controller.state_interfaces().items()
                    for interface in read if interface in self._interfaces_of(joint, False)]
        interfaces = _flatten(controller.state_interfaces())
        if not interfaces and isinstance(controller, CommandController) and (
                controller.pids()):
            # A PID loop reads the joint's position and velocity.
            interfaces = [f'{joint}/{interface}' for joint in controller.joint_names
                          for interface in ('position', 'velocity')]
        return interfaces


    # --- what a spawner may set ----------------------------------------------------------------

    @staticmethod
    def is_controller_field(name: str) -> bool:
        """Whether ``name`` is what a spawner sets per controller (``arm.type``, ...)."""
        controller, _, field = name.rpartition('.')
        return bool(controller) and field in CONTROLLER_FIELDS


class ControllerManagerNode(Node):
    """The controller_manager as a node of its own in sim_node's process (see the module)."""

    def __init__(self, model: RobotModel, namespace: str, *,
                 context: Context | None = None) -> None:
        # Not the process's global arguments: a `-r __node:=...` meant for sim_node
        # must not rename this node, nor its `-p` parameters land here.  Its name is
        # the control plugin's <controller_manager_name>, as gz_ros2_control names it.
        super().__init__(model.controller_manager_name, namespace=namespace or '/',
                         context=context,
                         use_global_arguments=False, allow_undeclared_parameters=True)
        self._model = model
        self.manager_services: ControllerManagerServices | None = None

    def serve(self, bindings: ControllerBindings, manager: ControllerManager, *,
              substitutions: Mapping[str, str] | None = None, source: str = '') -> None:
        """Offer the services for ``manager``'s controllers.

        Apart from the constructor: a spawned robot's gain parameters live on
        this node, and its controllers are bound with them before this.
        """
        self.manager_services = ControllerManagerServices(
            self, bindings, manager, self._model, substitutions=substitutions, source=source)

    @property
    def update_rate(self) -> int:
        """Hz at which the controllers update (the controller_manager's ``update_rate``)."""
        return self.manager_services.update_rate


def _flatten(interfaces: Mapping[str, Sequence[str]]) -> list[str]:
    return [f'{joint}/{interface}' for joint, names in interfaces.items() for interface in names]


def _without_prefix(interface: str) -> str:
    """``pid/joint1/position`` -> ``joint1/position``: a reference interface, as listed."""
    return interface.partition('/')[2]


def _is_strings(value: Any) -> bool:
    return isinstance(value, list | tuple) and all(isinstance(item, str) for item in value)


def _is_string_or_strings(value: Any) -> bool:
    return isinstance(value, str) or _is_strings(value)
