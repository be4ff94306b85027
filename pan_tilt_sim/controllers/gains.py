"""Reading a controller's PID gains from its YAML parameters."""

from __future__ import annotations

from pan_tilt_sim.controllers.base import Controller
from pan_tilt_sim.controllers.pid import GainsError, PidGains

PID_FIELD = 'pid'


def gains_from_params(controller: Controller, default: PidGains) -> PidGains:
    """Return the ``pid: {p, i, d, i_clamp...}`` section of ``controller``, or ``default``."""
    values = controller.params.get(PID_FIELD)
    if values is None:
        return default
    try:
        return PidGains.from_mapping(values)
    except GainsError as err:
        raise controller.error(PID_FIELD, str(err)) from None
