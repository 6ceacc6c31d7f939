"""Charged particle in the plane with a uniform magnetic field B along z (LNN section 2).

L = m/2 |v|^2 + (e B / 2)(x ydot - y xdot), symmetric gauge; parameters m > 0, charge ``e``
and field ``B`` (any real). The kinetic part has a term linear in qdot, so the Lagrangian
is not of DeLaN's form qdot^T M(q) qdot / 2 - V(q): ``mass_matrix`` raises, the velocity
Hessian is m I. Motion: m qddot = e B (ydot, -xdot) (circles of radius m|v|/(eB)).
"""

from __future__ import annotations

from lagbench.systems.definition import Definition, coordinates, param
from lagbench.systems.library._sampling import unknown


def build_charged_magnetic() -> Definition:
    q, v = coordinates(["x", "y"])
    p = {"m": param("m", 1.0), "e": param("e", 1.0, "real"), "B": param("B", 1.0, "real")}
    m, e, b = (p[k][0] for k in ("m", "e", "B"))
    lag = m / 2 * (v[0] ** 2 + v[1] ** 2) + e * b / 2 * (q[0] * v[1] - q[1] * v[0])

    def sampler(n, rng, params, distribution):
        if distribution != "default":
            raise unknown(distribution, ["default"])
        return {"q": rng.uniform(-1.0, 1.0, (n, 2)), "qdot": rng.normal(0.0, 1.0, (n, 2))}

    return Definition("charged_magnetic", q, v, lag, p, sampler,
                      description="charged particle in a uniform magnetic field (2D)")
