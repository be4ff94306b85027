"""registry: every YAML type string maps to a controller class that loads and runs.

Each registered type is loaded through the manager with nothing but its
spec's examples (everything else from the defaults), on a minimal four-joint
robot with the example sensor and gpio; it configures, activates, runs,
declares its ROS surface, and documents every parameter.
"""

import math

import pytest

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.framework.base import CommandController
from pan_tilt_sim.controllers.framework.hardware_interfaces import example_hardware
from pan_tilt_sim.controllers.framework.manager import ACTIVE, ControllerManager
from pan_tilt_sim.controllers.framework.parameter_spec import ParameterSpec
from pan_tilt_sim.controllers.framework.registry import CONTROLLER_TYPES, create_controller
from pan_tilt_sim.controllers.framework.surface import CommandTopic, Endpoint
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import ControllersConfig, ControllerSpec
from pan_tilt_sim.model.robot import JointKind, JointSpec

DT = 0.001

EXAMPLE_JOINTS = ('joint1', 'joint2', 'joint3', 'joint4')


def small_robot():
    """Return joint1 (every example's joint), joint2 to joint4 (a drive's other wheels).

    joint3 and joint4 are also the second traction and steering joints of the steering types.
    """
    return {name: JointHandle(JointSpec(name, JointKind.REVOLUTE, -1.0, 1.0, effort_limit=10.0,
                                        velocity_limit=2.0)) for name in EXAMPLE_JOINTS}


@pytest.mark.parametrize('type_name', sorted(CONTROLLER_TYPES))
def test_every_type_loads_with_its_spec_defaults_and_runs(type_name, tmp_path):
    cls = CONTROLLER_TYPES[type_name]
    params = {'type': type_name, **cls.parameters.example()}
    config = ControllersConfig((ControllerSpec('under_test', type_name, params),),
                               tmp_path / 'controllers.yaml')
    handles = small_robot()
    manager = ControllerManager(config, handles, hardware=example_hardware())
    controller = manager.controller('under_test')
    assert manager.state('under_test') == ACTIVE
    assert controller.config_warnings == []
    for step in range(20):
        for update in manager.updates:
            update(step * DT, DT)
        for _schedule, update in manager.scheduled_updates:
            update(step * DT, DT)
    handle = handles['joint1']
    assert all(map(math.isfinite, (handle.position, handle.velocity, handle.effort,
                                   handle.velocity_target)))
    surface = controller.ros_surface()
    assert surface, f'{type_name} declares no topic or action'
    if isinstance(controller, CommandController):
        assert any(isinstance(endpoint, CommandTopic) for endpoint in surface)
    assert all(isinstance(endpoint, Endpoint) for endpoint in surface)


@pytest.mark.parametrize('type_name', sorted(CONTROLLER_TYPES))
def test_every_type_documents_every_parameter(type_name):
    spec = CONTROLLER_TYPES[type_name].parameters
    assert isinstance(spec, ParameterSpec) and len(spec)
    for param in spec:
        assert param.description.endswith('.'), f'{type_name}: {param.name}'
        if param.required:
            assert param.example is not None, f'{type_name}: {param.name} has no example'


@pytest.mark.parametrize('type_name', sorted(CONTROLLER_TYPES))
def test_every_type_refuses_a_missing_required_parameter_naming_it(type_name):
    spec = CONTROLLER_TYPES[type_name].parameters
    for param in spec:
        if not param.required:
            continue
        params = {key: value for key, value in spec.example().items() if key != param.name}
        with pytest.raises(ControllerConfigError, match=rf'^f\.yaml: c\.{param.name}: missing'):
            create_controller('c', type_name, params, 'f.yaml')


def test_an_unknown_type_lists_the_supported_ones():
    with pytest.raises(ControllerConfigError, match=r'unknown controller type .* \(supported: '):
        create_controller('c', 'diff_drive_controller/DiffDriveControler', {}, 'f.yaml')
