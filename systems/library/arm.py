"""Planar two-link robot arm in a vertical plane with joint torques (DeLaN).

Joint angles: q1 of link 1 from the horizontal x axis, q2 of link 2 relative to link 1 (the
usual robotics convention); gravity g acts along -y in the arm's plane. Links are uniform
rods: mass m_i, length l_i, centre of mass at lc_i, inertia I_i about the centre of mass.
Defaults (a small realistic arm): m1 = 2.0 kg, m2 = 1.5 kg, l1 = 0.5 m, l2 = 0.4 m,
lc1 = 0.25 m, lc2 = 0.2 m, I1 = m1 l1^2 / 12, I2 = m2 l2^2 / 12, g = 9.81, viscous joint
friction ``friction`` = 0 (generalised force -friction * qdot). The torques tau are the
generalised forces of the joints: M(q) qddot + c(q, qdot) + g(q) = tau - friction qdot.
"""

from __future__ import annotations

import numpy as np

from lagbench.systems.definition import Definition, coordinates, param, planar_kinetic, planar_position
from lagbench.systems.library._sampling import unknown


def build_two_link_arm() -> Definition:
    q, v = coordinates(["q1", "q2"])
    p = {
        "m1": param("m1", 2.0), "m2": param("m2", 1.5),
        "l1": param("l1", 0.5), "l2": param("l2", 0.4),
        "lc1": param("lc1", 0.25), "lc2": param("lc2", 0.2),
        "I1": param("I1", 2.0 * 0.5**2 / 12), "I2": param("I2", 1.5 * 0.4**2 / 12),
        "g": param("g", 9.81, "nonnegative"), "friction": param("friction", 0.0, "nonnegative"),
    }
    m1, m2, l1, _, lc1, lc2, i1, i2, g, b = (p[k][0] for k in p)
    points = [[(lc1, q[0])], [(l1, q[0]), (lc2, q[0] + q[1])]]
    t = planar_kinetic(points, [m1, m2], q, v)
    t += i1 * v[0] ** 2 / 2 + i2 * (v[0] + v[1]) ** 2 / 2
    lag = t - g * sum(m * planar_position(p)[1] for m, p in zip((m1, m2), points, strict=True))

    def sampler(n, rng, params, distribution):
        if distribution != "default":
            raise unknown(distribution, ["default"])
        return {"q": rng.uniform(-np.pi, np.pi, (n, 2)), "qdot": rng.uniform(-3.0, 3.0, (n, 2))}

    def validate(values):
        for i in (1, 2):
            if values[f"lc{i}"] > values[f"l{i}"]:
                raise ValueError(f"two_link_arm: lc{i} (centre of mass) must not exceed l{i} (link length)")

    return Definition("two_link_arm", q, v, lag, p, sampler, forces=(-b * v[0], -b * v[1]),
                      actuated=True, validate=validate, description="planar 2-link arm with joint torques")
