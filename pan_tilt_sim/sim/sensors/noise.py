"""Gaussian sensor noise as Gazebo adds it: a per-run bias plus white noise. No ROS.

Each sensor draws from its own seeded generator (:func:`generator`), so a
run with a given seed is reproducible and sensors do not disturb each
other's draws.  The bias is drawn once, from N(bias_mean, bias_stddev), and
given a random sign, as Gazebo's GaussianNoiseModel does.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy

from pan_tilt_sim.model.sensors import Noise


def generator(seed: int | None, index: int) -> numpy.random.Generator:
    """Return sensor ``index``'s generator for run ``seed`` (None: from the OS)."""
    if seed is None:
        return numpy.random.default_rng()
    return numpy.random.default_rng([seed, index])


class NoiseModel:
    """Adds one :class:`Noise` per channel (x, y, z...) plus an extra white noise to all."""

    def __init__(self, noises: Sequence[Noise], rng: numpy.random.Generator,
                 extra_stddev: float = 0.0) -> None:
        self._rng = rng
        self._mean = numpy.array([noise.mean for noise in noises], dtype=float)
        bias = numpy.array([rng.normal(noise.bias_mean, noise.bias_stddev)
                            if noise.bias_stddev else noise.bias_mean for noise in noises])
        signs = numpy.where(rng.random(len(noises)) < 0.5, -1.0, 1.0)
        self._offset = self._mean + bias * signs
        self._stddev = numpy.hypot([noise.stddev for noise in noises], extra_stddev)
        self.active = bool(numpy.any(self._offset) or numpy.any(self._stddev))

    def apply(self, values: numpy.ndarray) -> numpy.ndarray:
        """Return ``values`` (channels along the last axis) with the noise added."""
        if not self.active:
            return values
        return values + self._offset + self._rng.standard_normal(values.shape) * self._stddev
