"""Relativistic particle (m = c = 1) in a uniform field g, two Lagrangians (LNN section 5).

- ``relativistic``: the paper's and code's L = (1 - qdot^2)^(-1/2) - 1 + g q, giving
  qddot = g (1 - qdot^2)^(5/2) / (1 + 2 qdot^2) and p = qdot (1 - qdot^2)^(-3/2);
- ``relativistic_standard``: the physical L = -(1 - qdot^2)^(1/2) + g q, giving
  qddot = g (1 - qdot^2)^(3/2) and p = gamma qdot.

Both require |qdot| < 1 (checked on concrete inputs). The field g is a parameter that the
original protocol draws per sample: ``sample_states`` returns "g" (n,), to be passed back as
``acceleration(q, qdot, g=g)``. Distribution (LNN code): q ~ U[-10, 10], g ~ N(0, 10^2),
qdot = speed tanh(2 N(0, 1)), ``speed`` a structural option of both (default the code's 0.99999; at 0.1 the
Lagrangian is within 0.4 % of quadratic in qdot and qdot within 1.5 % of the momentum: the regime where
DeLaN's form and an HNN on (q, qdot) hold, for positive controls on the particle itself).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from lagbench.systems.definition import Definition, coordinates, param
from lagbench.systems.library._sampling import unknown

SPEED = 0.99999   # the original code's velocity scale


def _sampler_at(speed: float):
    if not 0 < speed < 1:
        raise ValueError(f"relativistic speed must be in (0, 1) (units of c), got {speed!r}")

    def sampler(n, rng, params, distribution):
        if distribution != "default":
            raise unknown(distribution, ["default"])
        q = rng.uniform(-10.0, 10.0, (n, 1))
        g = rng.normal(0.0, 10.0, n)
        qdot = speed * np.tanh(2.0 * rng.normal(0.0, 1.0, (n, 1)))
        return {"q": q, "qdot": qdot, "g": g}
    return sampler


def _build(name: str, standard: bool, speed: float) -> Definition:
    q, v = coordinates(["x"])
    p = {"g": param("g", 1.0, "real")}
    g = p["g"][0]
    if standard:
        lag = -sp.sqrt(1 - v[0] ** 2) + g * q[0]
        text = "L = -(1 - qdot^2)^(1/2) + g q (standard)"
    else:
        lag = (1 - v[0] ** 2) ** sp.Rational(-1, 2) - 1 + g * q[0]
        text = "L = (1 - qdot^2)^(-1/2) - 1 + g q (the LNN paper's)"
    at = "" if speed == SPEED else f", speeds up to {speed:g} c"
    # the speed is an option only where it departs from the code's, so the default's cache keys are the code's
    return Definition(name, q, v, lag, p, _sampler_at(float(speed)), max_speed=1.0,
                      options={} if speed == SPEED else {"speed": float(speed)},
                      description=f"relativistic particle in a uniform field, {text}{at}")


def build_relativistic(speed: float = SPEED) -> Definition:
    return _build("relativistic", standard=False, speed=speed)


def build_relativistic_standard(speed: float = SPEED) -> Definition:
    return _build("relativistic_standard", standard=True, speed=speed)
