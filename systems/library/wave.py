"""1D wave equation on a periodic grid of n points (LNN section 5, Lagrangian graph network).

L = sum_i qdot_i^2 / 2 - (k / 2) sum_i (q_{i+1} - q_i)^2 (periodic), so
qddot_i = k (q_{i+1} - 2 q_i + q_{i-1}) exactly, with

- ``variant="code"`` (default, the original code): k = 1 / (2 dx), dx = 0.1 as hard-coded;
- ``variant="textbook"``: k = 1 / dx^2 (unit wave speed).

Options n (>= 3, default 10) and variant; parameter dx > 0. The conserved energy of each
variant is sum qdot^2/2 + (k/2) sum (q_{i+1} - q_i)^2. Coupling is local (nearest neighbours).
Default states: white noise N(0, 1) per site for q and qdot (the code's training data);
``distribution="pulse"`` gives the code's evaluation state, a Gaussian pulse
exp(-(x - 0.5)^2 / (2 * 0.05^2)) on linspace(0, 1, n) at rest (same for every sample).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from lagbench.systems.definition import Definition, coordinates, param
from lagbench.systems.library._sampling import unknown

VARIANTS = ("code", "textbook")


def build_wave(n: int = 10, variant: str = "code") -> Definition:
    n = int(n)
    if n < 3:
        raise ValueError(f"wave needs n >= 3 grid points; got {n}")
    if variant not in VARIANTS:
        raise ValueError(f"unknown wave variant {variant!r}; valid: {', '.join(VARIANTS)}")
    q, v = coordinates([f"u{i}" for i in range(n)])
    p = {"dx": param("dx", 0.1)}
    dx = p["dx"][0]
    k = 1 / (2 * dx) if variant == "code" else 1 / dx**2
    kinetic = sum(vi**2 for vi in v) / 2
    stretch = sum((q[(i + 1) % n] - q[i]) ** 2 for i in range(n))
    lag = kinetic - k / 2 * stretch

    def sampler(m, rng, params, distribution):
        if distribution == "default":
            return {"q": rng.normal(0.0, 1.0, (m, n)), "qdot": rng.normal(0.0, 1.0, (m, n))}
        if distribution == "pulse":
            x = np.linspace(0.0, 1.0, n)
            pulse = np.exp(-((x - 0.5) ** 2) / (2 * 0.05**2))
            return {"q": np.tile(pulse, (m, 1)), "qdot": np.zeros((m, n))}
        raise unknown(distribution, ["default", "pulse"])

    return Definition("wave", q, v, sp.sympify(lag), p, sampler, options={"n": n, "variant": variant},
                      local_coupling=True, description=f"periodic 1D wave, n={n}, {variant} coefficient")
