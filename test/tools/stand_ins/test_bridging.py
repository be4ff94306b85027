"""What parameter_bridge and image_bridge share: once handed over, they stay until stopped."""

from __future__ import annotations

from interrupting import interrupted_after_check


def test_a_bridge_interrupted_between_its_check_and_its_wait_stops_as_interrupted():
    # ros_gz_bridge's rclcpp::spin returns when SIGINT shuts the context down, and the
    # bridge exits 0; the stand-in's loop ends the same way wherever the signal lands.
    result = interrupted_after_check(
        'from pan_tilt_sim.tools.stand_ins.bridging import stay_until_stopped\n',
        'stay_until_stopped(node)')
    assert (result.returncode, result.stdout) == (0, 'returned\n'), result.stderr


# A simulation that never answers the hand-over: its node is in the graph but never spun.
SILENT_SIMULATION = '''
from rclpy.parameter_client import AsyncParameterClient
from simulation_interfaces.srv import SpawnEntity

simulation = rclpy.create_node('sim_node', context=context)
simulation.create_service(SpawnEntity, '~/spawn_entity', lambda request, response: response)
asked = []
sending = AsyncParameterClient.set_parameters
AsyncParameterClient.set_parameters = (
    lambda self, *a, **k: asked.append(1) or sending(self, *a, **k))
'''


def test_a_bridge_interrupted_while_it_hands_over_stops_as_interrupted_not_refused():
    result = interrupted_after_check(
        'from pan_tilt_sim.tools.stand_ins.bridging import hand_over\n',
        "print('exit code', hand_over(node, []))", setup=SILENT_SIMULATION, armed='asked')
    assert (result.returncode, result.stdout) == (0, 'exit code 0\nreturned\n'), result.stderr
