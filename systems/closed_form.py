"""Hand-written closed forms, independent of the SymPy derivation: references for tests and
benchmarks, and the LNN code's analytic double pendulum.

- ``double_pendulum_acceleration(q, qdot, m1=1, m2=1, l1=1, l2=1, g=9.8, xp=numpy)``:
  the Assencio form used by the LNN code (``analytical_fn``), arrays (..., 2) -> (..., 2);
  ``xp`` is ``numpy`` or ``jax.numpy``.
- ``double_pendulum_energy(q, qdot, ...)`` -> (...,): T + V with V = -(m1+m2) g l1 cos q1 - m2 g l2 cos q2.
- ``relativistic_acceleration(qdot, g, standard=False)``: g (1-qdot^2)^(5/2)/(1+2qdot^2) (paper)
  or g (1-qdot^2)^(3/2) (standard); ``relativistic_momentum(qdot, standard=False)``.
"""

from __future__ import annotations

import numpy as np


def double_pendulum_acceleration(q, qdot, m1=1.0, m2=1.0, l1=1.0, l2=1.0, g=9.8, xp=np):
    t1, t2 = q[..., 0], q[..., 1]
    w1, w2 = qdot[..., 0], qdot[..., 1]
    a1 = (l2 / l1) * (m2 / (m1 + m2)) * xp.cos(t1 - t2)
    a2 = (l1 / l2) * xp.cos(t1 - t2)
    f1 = -(l2 / l1) * (m2 / (m1 + m2)) * (w2**2) * xp.sin(t1 - t2) - (g / l1) * xp.sin(t1)
    f2 = (l1 / l2) * (w1**2) * xp.sin(t1 - t2) - (g / l2) * xp.sin(t2)
    g1 = (f1 - a1 * f2) / (1 - a1 * a2)
    g2 = (f2 - a2 * f1) / (1 - a1 * a2)
    return xp.stack([g1, g2], axis=-1)


def double_pendulum_energy(q, qdot, m1=1.0, m2=1.0, l1=1.0, l2=1.0, g=9.8, xp=np):
    t1, t2 = q[..., 0], q[..., 1]
    w1, w2 = qdot[..., 0], qdot[..., 1]
    kinetic = 0.5 * m1 * (l1 * w1) ** 2 + 0.5 * m2 * (
        (l1 * w1) ** 2 + (l2 * w2) ** 2 + 2 * l1 * l2 * w1 * w2 * xp.cos(t1 - t2)
    )
    y1 = -l1 * xp.cos(t1)
    y2 = y1 - l2 * xp.cos(t2)
    return kinetic + m1 * g * y1 + m2 * g * y2


def relativistic_acceleration(qdot, g, standard=False):
    s = 1 - qdot**2
    return g * s**1.5 if standard else g * s**2.5 / (1 + 2 * qdot**2)


def relativistic_momentum(qdot, standard=False):
    s = 1 - qdot**2
    return qdot / np.sqrt(s) if standard else qdot * s**-1.5
