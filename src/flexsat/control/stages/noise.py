"""Seeded, counter-based random numbers for the compiled stages (numba).

A stage's noise is a pure function of its ``seed`` and a draw counter it keeps in
its state: the same seed gives the same noise, in any process, whatever else runs,
with nothing allocated and no global random state. The generator is SplitMix64
(Steele, Lea and Flood, "Fast splittable pseudorandom number generators", 2014)
applied to the (seed, counter) pair; normal deviates by Box-Muller.
"""

from __future__ import annotations

from math import cos, log, pi, sqrt

import numpy as np
from numba import njit

__all__ = ["normal", "uniform"]

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_STREAM = np.uint64(0xD1B54A32D192ED03)


@njit(cache=True, inline="always")
def _mix(z):
    z = z + _GOLDEN
    z = (z ^ (z >> np.uint64(30))) * _M1
    z = (z ^ (z >> np.uint64(27))) * _M2
    return z ^ (z >> np.uint64(31))


@njit(cache=True)
def uniform(seed, counter):
    """A uniform deviate in (0, 1) from integers ``seed`` and ``counter``.

    Parameters
    ----------
    seed : float
        The stream, a float holding an integer below 2**53 [-].
    counter : float
        The draw, a float holding an integer below 2**53 [-].

    Returns
    -------
    float
        The deviate [-].
    """
    z = _mix(_mix(np.uint64(seed)) * _STREAM ^ _mix(np.uint64(counter)))
    return (float(z >> np.uint64(11)) + 0.5) * 2.0**-53


@njit(cache=True)
def normal(seed, counter):
    """A standard normal deviate, draw ``counter`` of stream ``seed``.

    Box-Muller on the uniform draws 2 counter and 2 counter + 1.

    Parameters
    ----------
    seed : float
        The stream, a float holding an integer below 2**53 [-].
    counter : float
        The draw, a float holding an integer below 2**52 [-].

    Returns
    -------
    float
        The deviate, zero mean and unit variance [-].
    """
    u1 = uniform(seed, 2.0 * counter)
    u2 = uniform(seed, 2.0 * counter + 1.0)
    return sqrt(-2.0 * log(u1)) * cos(2.0 * pi * u2)
