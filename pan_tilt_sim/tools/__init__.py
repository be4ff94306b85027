"""Tools around the simulator: step_response, bench, launch-file helpers."""
