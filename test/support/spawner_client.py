"""A test client that calls controller_manager the way jazzy's spawner.py does.

:class:`Spawner` works on anything with ``call``, ``probe`` and
``spin_until`` (test/support/node_harness.py's NodeHarness and SimUnderTest).
"""

from __future__ import annotations

from builtin_interfaces.msg import Duration
from rclpy.parameter import Parameter, get_parameter_value
from rclpy.parameter_client import AsyncParameterClient

CM = '/controller_manager'
STRICT, BEST_EFFORT = 2, 1


def srv():
    from controller_manager_msgs import srv as module

    return module


class Spawner:
    """The calls of jazzy's spawner.py, from the harness's probe node."""

    def __init__(self, sim, manager: str = CM, namespace: str = '/') -> None:
        self.sim = sim
        self.manager = manager
        self.namespace = namespace  # the spawner's: its files' keys may name it

    def call(self, service: str, request=None):
        service_type = {'list_controllers': srv().ListControllers,
                        'load_controller': srv().LoadController,
                        'configure_controller': srv().ConfigureController,
                        'switch_controller': srv().SwitchController,
                        'unload_controller': srv().UnloadController,
                        'cleanup_controller': srv().CleanupController,
                        'list_hardware_interfaces': srv().ListHardwareInterfaces,
                        'list_hardware_components': srv().ListHardwareComponents,
                        'list_controller_types': srv().ListControllerTypes,
                        'reload_controller_libraries': srv().ReloadControllerLibraries,
                        }[service]
        return self.sim.call(service_type, f'{self.manager}/{service}', request)

    def controllers(self) -> dict[str, object]:
        return {c.name: c for c in self.call('list_controllers').controller}

    def set_parameter(self, controller: str, name: str, value) -> bool:
        """As the spawner's set_controller_parameters: str(value) through yaml, one Parameter."""
        client = AsyncParameterClient(self.sim.probe, self.manager)
        assert self.sim.spin_until(client.services_are_ready), 'parameter services not ready'
        parameter = Parameter(f'{controller}.{name}').to_parameter_msg()
        parameter.value = get_parameter_value(str(value))
        future = client.set_parameters([parameter])
        assert self.sim.spin_until(future.done)
        (result,) = future.result().results
        return result.successful

    def load(self, name: str) -> bool:
        return self.call('load_controller', srv().LoadController.Request(name=name)).ok

    def configure(self, name: str) -> bool:
        return self.call('configure_controller', srv().ConfigureController.Request(name=name)).ok

    def switch(self, activate=(), deactivate=(), strictness=STRICT):
        request = srv().SwitchController.Request(
            activate_controllers=list(activate), deactivate_controllers=list(deactivate),
            strictness=strictness, activate_asap=True, timeout=Duration(sec=5))
        return self.call('switch_controller', request)

    def spawn(self, name: str, param_files=(), controller_ros_args=(), *,
              inactive: bool = False) -> int:
        """Jazzy spawner.py's main() for one controller; return its exit code.

        ``controller_ros_args`` are its ``--controller-ros-args`` (each split
        on spaces, as the spawner splits them) and ``param_files`` its
        ``--param-file``s: the files with a section for the controller
        become its ``params_file``, and the first ``type`` in them its type.
        """
        if name in self.controllers():
            pass  # "Controller already loaded, skipping load_controller"
        else:
            if controller_ros_args:
                words = [word for args in controller_ros_args for word in args.split()]
                if not self.set_parameter(name, 'node_options_args', words):
                    return 1
            ns = self.namespace
            files = [str(path) for path in param_files if _section(path, name, ns) is not None]
            if files:
                self.set_parameter(name, 'params_file', files)
                kind = next((_section(path, name, ns).get('type') for path in files
                             if _section(path, name, ns).get('type')), None)
                if kind and not self.set_parameter(name, 'type', kind):
                    return 1
            if not self.load(name):
                return 1
        if not self.configure(name):
            return 1
        if inactive:
            return 0
        return 0 if self.switch(activate=[name]).ok else 1


def _section(path, name: str, namespace: str = '/') -> dict | None:
    """The controller's ros__parameters in a parameter file (its key or /**), else None."""
    import yaml

    with open(path) as stream:
        document = yaml.safe_load(stream) or {}
    namespaced = f"{namespace.rstrip('/')}/{name}"
    for key in (name, namespaced, f'/**/{name}', f'/**{namespaced}'):
        if key in document:
            return document[key].get('ros__parameters') or {}
    wildcard = document.get('/**') or {}
    if name in wildcard:
        return wildcard[name].get('ros__parameters') or {}
    if 'ros__parameters' in wildcard:
        return wildcard['ros__parameters'] or {}
    return None


def spawner_main(sim, arguments, namespace: str = '/') -> int:
    """Jazzy spawner.py run with ``arguments`` (its native mode) by a node in ``namespace``."""
    import argparse

    parser = argparse.ArgumentParser()
    parser.add_argument('controller_names', nargs='+')
    parser.add_argument('-c', '--controller-manager', default='controller_manager')
    parser.add_argument('-p', '--param-file', action='append', default=[])
    parser.add_argument('--inactive', action='store_true')
    parser.add_argument('--controller-ros-args', action='append', default=[])
    args = parser.parse_args([str(argument) for argument in arguments])
    namespace = '/' + namespace.strip('/')  # as the spawner makes its namespace absolute
    manager = args.controller_manager
    if not manager.startswith('/'):
        manager = f"{namespace.rstrip('/')}/{manager}"
    spawner = Spawner(sim, manager, namespace)
    for name in args.controller_names:
        code = spawner.spawn(name, args.param_file, args.controller_ros_args,
                             inactive=args.inactive)
        if code:
            return code
    return 0
