"""The <ros2_control> sensors and gpios, simulated, against the truth of the sensor arm.

See test/support/hardware_fixtures.py: a payload of known mass below a force-torque
sensor, an IMU at rest, a range ray looking down at the ground, a pose, a
gpio, and entries the simulator cannot produce.
"""

import math

import numpy
import pytest
from hardware_fixtures import (
    ARM_URDF,
    CONTROLLERS_YAML,
    FT_HEIGHT,
    HAND_MASS,
    PAYLOAD_MASS,
    PAYLOAD_OFFSET,
    RANGE_HEIGHT,
    RANGE_X,
    SHOULDER_Z,
    TEMPERATURE,
    VACUUM_START,
    controllers_without,
    write_sensor_arm,
)

from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.physics import STANDARD_GRAVITY

TIME_STEP = 0.001
ONE_PERCENT = 0.01
IMU_RADIUS = 0.2  # m: the imu_link above the shoulder, on the upper arm


class Log:
    """A logger keeping what the simulation says."""

    def __init__(self):
        self.lines = []

    def info(self, message):
        self.lines.append(('info', message))

    def warning(self, message):
        self.lines.append(('warning', message))


@pytest.fixture
def arm(tmp_path):
    built = []

    def build(urdf=ARM_URDF, controllers=CONTROLLERS_YAML, log=None):
        paths = write_sensor_arm(tmp_path, urdf, controllers)
        built.append(make_simulation(*map(str, paths), TIME_STEP, logger=log))
        return built[-1]
    yield build
    for simulation in built:
        simulation.close()


def listen(simulation, controller, topic):
    """Connect a sink to ``controller``'s ``topic``; return the list its samples go to."""
    samples = []
    endpoint = next(e for e in simulation.controller(controller).ros_surface()
                    if e.name == topic)
    endpoint.connect(lambda time, *values: samples.append(
        (round(time, 6), *[numpy.array(value, dtype=float) for value in values])))
    return samples


# --- force-torque --------------------------------------------------------------------------

def test_the_payload_held_still_shows_its_weight_on_the_wrench_within_one_percent(arm):
    simulation = arm()
    samples = listen(simulation, 'ft_broadcaster', '~/wrench')
    simulation.advance(300)
    _time, force, torque = samples[-1]
    weight = PAYLOAD_MASS * STANDARD_GRAVITY
    # In the ft_link's axes (the world's here), child on parent: the payload pulls down.
    assert force == pytest.approx((0.0, 0.0, -weight), rel=ONE_PERCENT, abs=ONE_PERCENT * weight)
    # Its centre of mass is PAYLOAD_OFFSET along x: its weight's moment about the sensor.
    assert torque == pytest.approx((0.0, PAYLOAD_OFFSET * weight, 0.0), rel=ONE_PERCENT,
                                   abs=1e-6)


def test_a_sensor_the_urdf_does_not_place_sits_at_its_broadcasters_frame_id(arm):
    simulation = arm()
    samples = listen(simulation, 'tcp_broadcaster', '~/wrench')
    simulation.advance(300)
    _time, force, _torque = samples[-1]
    # On the hand: the wrist carries the hand, the massless ft_link and the payload.
    assert force[2] == pytest.approx(-(HAND_MASS + PAYLOAD_MASS) * STANDARD_GRAVITY,
                                     rel=ONE_PERCENT)


def test_a_frame_id_naming_another_link_gets_the_wrench_expressed_there(arm):
    simulation = arm()
    sensor = simulation.hardware.interfaces.sensors['ft_sensor']
    # range_link: on the base, RANGE_X out along x, its x pointing down, its z along world x.
    assert sensor.use_frame('range_link') is None
    sensor.watch('test', True)
    simulation.advance(300)
    assert sensor.refresh(simulation.time)
    value = {name: interface.value for name, interface in sensor.interfaces.items()}
    weight = PAYLOAD_MASS * STANDARD_GRAVITY
    # The payload's pull, straight down, is along the range_link's +x.
    assert (value['force.x'], value['force.y'], value['force.z']) == pytest.approx(
        (weight, 0.0, 0.0), abs=ONE_PERCENT * weight)
    # About the range_link's origin the pull's lever is the payload's x less RANGE_X.
    assert value['torque.y'] == pytest.approx((PAYLOAD_OFFSET - RANGE_X) * weight,
                                              rel=ONE_PERCENT)
    assert sensor.use_frame('no_such_link') == (
        "is not a link of the robot: the wrench is given in 'ft_link'")


def test_the_first_wrench_after_someone_listens_is_skipped_then_every_sample_comes(arm):
    simulation = arm()
    simulation.advance(100)
    samples = listen(simulation, 'ft_broadcaster', '~/wrench')
    simulation.advance(50)
    # The joint feedback was off until now: the sample at 0.1 s would have read nothing.
    assert [time for time, *_ in samples] == [0.11, 0.12, 0.13, 0.14]


def test_an_unwatched_sensor_keeps_pybullets_joint_feedback_off(arm):
    simulation = arm()
    source = simulation.hardware.sensors[0]
    assert source.control.name == 'ft_sensor'
    assert not source.feedback_on
    endpoint = simulation.controller('ft_broadcaster').ros_surface()[0]
    endpoint.connect(lambda *sample: None)
    assert source.feedback_on
    endpoint.connect(None)
    assert not source.feedback_on


GAZEBO_FT = """
  <gazebo reference="ft_joint">
    <sensor name="ft_sensor" type="force_torque">
      <update_rate>20</update_rate>
      <force_torque><frame>child</frame><measure_direction>parent_to_child</measure_direction>
      </force_torque>
    </sensor>
  </gazebo>
</robot>"""


def test_a_gazebo_sensor_of_the_same_name_brings_its_direction_and_rate(arm):
    simulation = arm(ARM_URDF.replace('</robot>', GAZEBO_FT))
    samples = listen(simulation, 'ft_broadcaster', '~/wrench')
    simulation.advance(300)
    # parent_to_child: what the hand holds the payload up with.
    assert samples[-1][1][2] == pytest.approx(PAYLOAD_MASS * STANDARD_GRAVITY, rel=ONE_PERCENT)
    simulation.controller('arm_controller').set_command([0.5, 0.0])
    simulation.advance(200)
    # 100 Hz samples of a 20 Hz sensor: each reading stays for five samples.
    recent = [sample[1][0] for sample in samples[-20:]]
    changes = sum(1 for before, after in zip(recent, recent[1:], strict=False)
                  if before != after)
    assert 2 <= changes <= 4


NOISY_FT = """
  <gazebo reference="ft_joint">
    <sensor name="ft_sensor" type="force_torque">
      <force_torque><force><x><noise type="gaussian"><mean>0.0</mean><stddev>0.5</stddev>
      </noise></x></force></force_torque>
    </sensor>
  </gazebo>
</robot>"""


def force_x_readings(simulation, count):
    sensor = simulation.hardware.interfaces.sensors['ft_sensor']
    sensor.watch('test', True)
    readings = []
    for _ in range(count + 1):
        simulation.advance(1)
        if sensor.refresh(simulation.time):
            readings.append(sensor.interfaces['force.x'].value)
    sensor.watch('test', False)
    return numpy.array(readings)


def test_a_gazebo_sensors_noise_applies_and_a_seed_repeats_it(arm):
    runs = []
    for _ in range(2):
        simulation = arm(ARM_URDF.replace('</robot>', NOISY_FT))
        simulation.hardware.configure(seed=7)
        runs.append(force_x_readings(simulation, 400))
    assert runs[0].std() == pytest.approx(0.5, rel=0.15)
    assert numpy.array_equal(runs[0], runs[1])


def test_a_sensor_on_a_link_that_carries_nothing_says_it_reads_zero(arm):
    log = Log()
    arm(ARM_URDF.replace('<param name="frame_id">ft_link</param>',
                         '<param name="frame_id">imu_link</param>'), log=log)
    assert ('info', "sensor 'ft_sensor': the wrench on joint 'imu_joint' (nothing beyond it "
            "has mass: 0 until something pushes on it) at 'imu_link' (<param "
            'name="frame_id">imu_link</param>)') in log.lines


# --- IMU, range, pose ----------------------------------------------------------------------

def test_an_imu_at_rest_reads_gravity_up_and_no_rotation(arm):
    simulation = arm()
    samples = listen(simulation, 'imu_broadcaster', '~/imu')
    simulation.advance(300)
    _time, orientation, angular, linear = samples[-1]
    assert linear == pytest.approx((0.0, 0.0, STANDARD_GRAVITY), rel=ONE_PERCENT, abs=1e-6)
    assert angular == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
    assert orientation == pytest.approx((0.0, 0.0, 0.0, 1.0), abs=1e-9)


def test_an_imu_swung_at_a_steady_rate_reads_gravity_and_the_centripetal_pull(arm):
    simulation = arm()
    samples = listen(simulation, 'imu_broadcaster', '~/imu')
    simulation.advance(300)
    simulation.controller('arm_controller').set_command([1.0, 0.0])  # the shoulder swings
    simulation.advance(301)  # to mid-swing, at the velocity limit; a sample at the last step
    _time, _orientation, angular, linear = samples[-1]
    rate = angular[1]
    assert rate == pytest.approx(simulation.joint_velocities()['shoulder'], rel=ONE_PERCENT)
    assert rate == pytest.approx(2.0, rel=ONE_PERCENT)  # the joint's limit: a steady swing
    lean = simulation.joint_positions()['shoulder']
    # On the upper arm IMU_RADIUS from the shoulder, its z along the arm: gravity's share
    # along z, less the pull towards the shoulder; gravity's other share along -x.
    assert linear[2] == pytest.approx(STANDARD_GRAVITY * math.cos(lean) - rate**2 * IMU_RADIUS,
                                      rel=ONE_PERCENT)
    assert linear[0] == pytest.approx(-STANDARD_GRAVITY * math.sin(lean), rel=ONE_PERCENT)


def test_the_first_imu_sample_after_someone_listens_waits_for_an_earlier_velocity(arm):
    simulation = arm()
    simulation.advance(100)
    samples = listen(simulation, 'imu_broadcaster', '~/imu')
    simulation.advance(30)
    assert [time for time, *_ in samples] == [0.11, 0.12]


def test_the_range_ray_meets_the_ground_below_it_and_nothing_without_one(arm):
    simulation = arm()
    samples = listen(simulation, 'range_broadcaster', '~/range')
    simulation.advance(20)
    assert math.isinf(samples[-1][1])
    simulation.hardware.configure(world='ground')
    simulation.advance(20)
    assert float(samples[-1][1]) == pytest.approx(RANGE_HEIGHT, rel=1e-4)


def test_the_pose_is_the_sensor_links_in_the_world(arm):
    simulation = arm()
    samples = listen(simulation, 'pose_broadcaster', '~/pose')
    simulation.advance(20)
    _time, position, orientation = samples[-1]
    assert position == pytest.approx((0.0, 0.0, FT_HEIGHT), abs=1e-6)
    assert orientation == pytest.approx((0.0, 0.0, 0.0, 1.0), abs=1e-6)
    simulation.controller('arm_controller').set_command([0.5, 0.0])  # the shoulder leans
    simulation.advance(1000)
    _time, position, _orientation = samples[-1]
    reach = FT_HEIGHT - SHOULDER_Z
    assert position == pytest.approx((reach * math.sin(0.5), 0.0,
                                      SHOULDER_Z + reach * math.cos(0.5)), abs=1e-3)


# --- gpio, and what is not simulated -------------------------------------------------------

def test_a_gpio_command_is_echoed_and_an_input_keeps_its_initial_value(arm):
    simulation = arm()
    samples = listen(simulation, 'gpio_controller', '~/gpio_states')
    simulation.advance(5)
    (vacuum, pressure), = samples[-1][1]
    assert vacuum == VACUUM_START and math.isnan(pressure)
    simulation.controller('gpio_controller').set_command((['tool_io'], [(['vacuum'], [0.0])]))
    simulation.advance(30)
    assert samples[-1][1][0][0] == 0.0
    simulation.reset()
    simulation.advance(1)
    assert samples[-1][1][0][0] == VACUUM_START


def test_mock_gpio_commands_gives_every_gpio_state_a_command_interface(arm):
    simulation = arm(ARM_URDF.replace(
        '<plugin>mock_components/GenericSystem</plugin>',
        '<plugin>mock_components/GenericSystem</plugin>'
        '<param name="mock_gpio_commands">true</param>'))
    interfaces = simulation.hardware.interfaces
    assert list(interfaces.command_interfaces) == ['tool_io/vacuum', 'tool_io/pressure']
    interfaces.command_interfaces['tool_io/pressure'].write(2.5)
    assert interfaces.state_interfaces['tool_io/pressure'].value == 2.5


def test_what_cannot_be_simulated_is_warned_about_once_at_start_up(arm):
    log = Log()
    simulation = arm(log=log)
    warnings = [line for level, line in log.lines if level == 'warning']
    assert warnings == [
        "sensor 'thermometer': state interface temperature is not simulated: it keeps its "
        'initial_value (NaN where none is given)',
        "gpio 'tool_io': state interface pressure has no command interface to echo and "
        'nothing in the simulation drives it: it keeps its initial_value (NaN where none is '
        "given), as mock hardware's do"]
    infos = [line for level, line in log.lines if level == 'info']
    assert ("sensor 'tcp_fts_sensor': the wrench on joint 'wrist' at 'hand' (its "
            "broadcaster's frame_id)") in infos
    assert simulation.hardware.interfaces.state_interfaces[
        'thermometer/temperature'].value == TEMPERATURE


def test_a_sensor_nothing_places_is_warned_about_and_reads_nan(arm):
    log = Log()
    # Without its broadcaster, nothing places tcp_fts_sensor.
    simulation = arm(controllers=controllers_without('tcp_broadcaster'), log=log)
    assert ('warning', "sensor 'tcp_fts_sensor' is not placed: no Gazebo <sensor> of its "
            'name, it has no <param name="frame_id">, and no link has its name: it reads NaN '
            "until a broadcaster's frame_id names a link for it") in log.lines
    sensor = simulation.hardware.interfaces.sensors['tcp_fts_sensor']
    sensor.watch('test', True)
    simulation.advance(10)
    assert sensor.refresh(simulation.time)
    assert all(math.isnan(interface.value) for interface in sensor.interfaces.values())
