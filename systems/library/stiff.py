"""A stiff spring chain: the hard case for the ground-truth integrators ("stiff springs", SPEC).

``stiff_chain``: two unit masses on a line, wall -- k_soft -- m1 -- k_stiff -- m2, coordinates the
displacements x1, x2 from rest. L = m/2 (x1dot^2 + x2dot^2) - k_soft/2 x1^2 - k_stiff/2 (x2 - x1)^2.
Defaults k_soft = 1, k_stiff = 1e4: a spring stiffness ratio of 1e4. The normal-mode frequencies are
about sqrt(k_soft / 2m) = 0.71 and sqrt(2 k_stiff / m) = 141 rad/s, so the eigenvalues +-i omega of the
linearised first-order dynamics span a ratio of about 200 (purely imaginary: oscillatory stiffness).

Sampler ("default"): x1 ~ U(-1, 1), stiff extension x2 - x1 ~ U(-1, 1) * sqrt(k_soft / k_stiff) so
that both modes carry comparable energy; velocities N(0, 1) on x1 and x1dot + N(0, 1) on x2.
"""

from __future__ import annotations

import numpy as np

from lagbench.systems.definition import Definition, coordinates, param
from lagbench.systems.library._sampling import unknown


def build_stiff_chain() -> Definition:
    q, v = coordinates(["x1", "x2"])
    p = {"m": param("m", 1.0), "k_soft": param("k_soft", 1.0), "k_stiff": param("k_stiff", 1e4)}
    m, k, kk = (p[n][0] for n in ("m", "k_soft", "k_stiff"))
    lag = m / 2 * (v[0] ** 2 + v[1] ** 2) - k / 2 * q[0] ** 2 - kk / 2 * (q[1] - q[0]) ** 2

    def sampler(n, rng, params, distribution):
        if distribution != "default":
            raise unknown(distribution, ["default"])
        x1 = rng.uniform(-1.0, 1.0, n)
        ext = rng.uniform(-1.0, 1.0, n) * np.sqrt(params["k_soft"] / params["k_stiff"])
        v1 = rng.normal(0.0, 1.0, n)
        v2 = v1 + rng.normal(0.0, 1.0, n)
        return {"q": np.stack([x1, x1 + ext], 1), "qdot": np.stack([v1, v2], 1)}

    return Definition("stiff_chain", q, v, lag, p, sampler,
                      description="two masses, a soft spring to the wall and a stiff one between them "
                                  "(stiffness ratio k_stiff / k_soft = 1e4)")
