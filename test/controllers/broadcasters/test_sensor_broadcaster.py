"""sensor_broadcaster: what every sensor broadcaster shares (shown with the range broadcaster).

It samples at its update rate, only while someone listens; a sensor is watched
exactly while a listener is connected; a sample waits for valid readings;
the frame_id goes to the sensors, and what they cannot do with it becomes a
notice.
"""

import pytest
from controller_fixtures import DT, FakeSource, hardware, loaded, sample_sink, sensor

from pan_tilt_sim.controllers.framework.manager import ACTIVE

TYPE = 'range_sensor_broadcaster/RangeSensorBroadcaster'
PARAMS = {'sensor_name': 'sonar', 'frame_id': 'sonar_link', 'update_rate': 50}


def configured(source: FakeSource):
    manager = loaded('range', TYPE, PARAMS, {}, hardware(sensor('sonar', ['range'], source)))
    manager.configure('range')
    manager.switch(['range'])
    return manager, manager.controller('range')


def run(manager, steps: int) -> None:
    for number in range(steps):
        for _schedule, update in manager.scheduled_updates:
            update(number * DT, DT)


def test_samples_at_its_update_rate_while_someone_listens():
    source = FakeSource({'range': 1.25})
    manager, controller = configured(source)
    samples = []
    controller.connect('~/range')(sample_sink(samples))
    run(manager, 61)
    assert [round(time, 6) for time, _ in samples] == [0.0, 0.02, 0.04, 0.06]
    assert {value for _, value in samples} == {1.25}
    assert source.refreshed == [time for time, _ in samples]


def test_nobody_listening_no_sample_and_the_sensor_is_not_watched():
    source = FakeSource({'range': 1.25})
    manager, controller = configured(source)
    assert manager.state('range') == ACTIVE
    assert not source.watched
    run(manager, 100)
    assert source.refreshed == []
    connect = controller.connect('~/range')
    connect(sample_sink([]))
    assert source.watched
    connect(None)
    assert not source.watched


def test_a_sample_waits_for_a_valid_reading():
    source = FakeSource({'range': 0.5})
    source.valid = False
    manager, controller = configured(source)
    samples = []
    controller.connect('~/range')(sample_sink(samples))
    run(manager, 30)
    assert samples == [] and len(source.refreshed) == 2
    source.valid = True
    run(manager, 50)
    assert samples


def test_the_frame_id_goes_to_the_sensor_and_its_problem_becomes_a_notice():
    source = FakeSource(problem='is not a link of the robot')
    _manager, controller = configured(source)
    assert source.frames == ['sonar_link']
    assert controller.notices == ["frame_id 'sonar_link': is not a link of the robot"]


def test_it_claims_the_state_interfaces_it_reads_and_no_command_interface():
    _manager, controller = configured(FakeSource())
    assert controller.state_interfaces() == {'sonar': ('range',)}
    assert controller.command_interfaces() == {}


@pytest.mark.parametrize('rate', [None, 100])
def test_without_an_update_rate_it_runs_at_the_controller_managers_default(rate):
    params = {key: value for key, value in PARAMS.items() if key != 'update_rate'}
    if rate:
        params['update_rate'] = rate
    manager = loaded('range', TYPE, params, {}, hardware(sensor('sonar', ['range'])))
    manager.configure('range')
    assert manager.controller('range').schedule().period == pytest.approx(0.01)
