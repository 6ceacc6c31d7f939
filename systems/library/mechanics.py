"""Point-mass mechanics: free fall (LNN App. B), pendulum and mass-spring (HNN tasks), the double
pendulum (LNN section 5) and the N-link pendulum chain.

Conventions: pendulum angles are absolute, measured from the downward vertical; free fall's
first coordinate is vertical (L = m/2 (qdot_1^2 + qdot_2^2) - m g q_1, so qddot = (-g, 0)).
Defaults: double pendulum m1 = m2 = l1 = l2 = 1, g = 9.8 (the LNN code); pendulum m = l = 1,
g = 3 (HNN's constants; HNN's written Hamiltonian 2mgl(1 - cos q) + l^2 p^2/2m corresponds to
g = 6 here); spring m = k = 1 (HNN). Pendulum and chain take a viscous ``friction`` >= 0
(default 0) as a generalised force -friction * qdot.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from lagbench.systems.definition import Definition, coordinates, param, planar_kinetic, planar_position
from lagbench.systems.library._sampling import ring, unknown


def build_free_fall() -> Definition:
    q, v = coordinates(["x1", "x2"])
    m, g = param("m", 1.0), param("g", 9.8)
    ms, gs = m[0], g[0]
    lag = ms / 2 * (v[0] ** 2 + v[1] ** 2) - ms * gs * q[0]

    def sampler(n, rng, params, distribution):
        if distribution != "default":
            raise unknown(distribution, ["default"])
        return {"q": rng.uniform(-1, 1, (n, 2)), "qdot": rng.normal(0, 1, (n, 2))}

    return Definition("free_fall", q, v, lag, {"m": m, "g": g}, sampler,
                      description="2D free fall, first coordinate vertical (LNN Appendix B)")


def build_pendulum() -> Definition:
    q, v = coordinates(["theta"])
    p = {"m": param("m", 1.0), "l": param("l", 1.0), "g": param("g", 3.0),
         "friction": param("friction", 0.0, "nonnegative")}
    m, l, g, b = (p[k][0] for k in ("m", "l", "g", "friction"))
    lag = m * l**2 * v[0] ** 2 / 2 + m * g * l * sp.cos(q[0])

    def sampler(n, rng, params, distribution):
        if distribution != "default":
            raise unknown(distribution, ["default"])
        x, y = ring(n, rng, 1.3, 2.3)  # HNN: (q, p) on a ring of radius U[1.3, 2.3)
        mom = y / (params["m"] * params["l"] ** 2)
        return {"q": x[:, None], "qdot": mom[:, None]}

    return Definition("pendulum", q, v, lag, p, sampler, forces=(-b * v[0],),
                      description="simple pendulum, angle from the downward vertical")


def build_spring() -> Definition:
    q, v = coordinates(["x"])
    p = {"m": param("m", 1.0), "k": param("k", 1.0)}
    m, k = p["m"][0], p["k"][0]
    lag = m * v[0] ** 2 / 2 - k * q[0] ** 2 / 2

    def sampler(n, rng, params, distribution):
        if distribution != "default":
            raise unknown(distribution, ["default"])
        x, y = ring(n, rng, 0.1, 1.0)  # HNN: radius U[0.1, 1.0)
        return {"q": x[:, None], "qdot": (y / params["m"])[:, None]}

    return Definition("spring", q, v, lag, p, sampler, description="mass on a linear spring")


def _double_pendulum_sampler(n, rng, params, distribution):
    th = rng.uniform(0.0, 2 * np.pi, (n, 2))
    if distribution == "default":  # the LNN code's training distribution
        return {"q": th, "qdot": rng.uniform(-10.0, 10.0, (n, 2))}
    if distribution == "near_rest":  # the LNN code's energy-evaluation starts
        return {"q": th, "qdot": rng.uniform(0.0, 0.1, (n, 2))}
    raise unknown(distribution, ["default", "near_rest"])


def build_double_pendulum() -> Definition:
    q, v = coordinates(["theta1", "theta2"])
    p = {k: param(k, 1.0) for k in ("m1", "m2", "l1", "l2")}
    p["g"] = param("g", 9.8)
    p["friction"] = param("friction", 0.0, "nonnegative")   # viscous, on each absolute angle: -friction * qdot
    m1, m2, l1, l2, g, b = (p[k][0] for k in ("m1", "m2", "l1", "l2", "g", "friction"))
    # angle from the downward vertical = polar angle theta - pi/2
    links = [(l1, q[0] - sp.pi / 2), (l2, q[1] - sp.pi / 2)]
    points = [links[:1], links]
    t = planar_kinetic(points, [m1, m2], q, v)
    y1, y2 = (planar_position(p)[1] for p in points)
    lag = t - (m1 * g * y1 + m2 * g * y2)
    return Definition("double_pendulum", q, v, lag, p, _double_pendulum_sampler, forces=(-b * v[0], -b * v[1]),
                      description="double pendulum, absolute angles from the downward vertical")


def build_pendulum_chain(n: int = 3) -> Definition:
    n = int(n)
    if n < 1:
        raise ValueError(f"pendulum_chain needs n >= 1 links; got {n}")
    q, v = coordinates([f"theta{i + 1}" for i in range(n)])
    p = {"m": param("m", 1.0), "l": param("l", 1.0), "g": param("g", 9.8),
         "friction": param("friction", 0.0, "nonnegative")}
    m, l, g, b = (p[k][0] for k in ("m", "l", "g", "friction"))
    links = [(l, th - sp.pi / 2) for th in q]
    points = [links[: k + 1] for k in range(n)]
    t = planar_kinetic(points, [m] * n, q, v)
    lag = t - sum(m * g * planar_position(p)[1] for p in points)

    def sampler(k, rng, params, distribution):
        th = rng.uniform(0.0, 2 * np.pi, (k, n))
        if distribution == "default":
            return {"q": th, "qdot": rng.uniform(-2.0, 2.0, (k, n))}
        if distribution == "near_rest":
            return {"q": th, "qdot": rng.uniform(0.0, 0.1, (k, n))}
        raise unknown(distribution, ["default", "near_rest"])

    return Definition("pendulum_chain", q, v, lag, p, sampler, forces=tuple(-b * vi for vi in v),
                      options={"n": n}, description=f"{n}-link pendulum chain, absolute angles")
