"""Small helpers shared by the samplers of the system families.

``sampler(n, rng, params, distribution) -> dict`` is the protocol (see ``systems.definition``);
``unknown(distribution, valid)`` raises the ValueError every sampler gives for a bad name.
"""

from __future__ import annotations

import numpy as np


def unknown(distribution: str, valid) -> ValueError:
    return ValueError(f"unknown state distribution {distribution!r}; valid: {', '.join(valid)}")


def ring(n: int, rng: np.random.Generator, r_low: float, r_high: float) -> tuple[np.ndarray, np.ndarray]:
    """HNN-style phase-space ring: radius U[r_low, r_high), angle U[0, 2pi). Returns (x, y), each (n,)."""
    r = rng.uniform(r_low, r_high, n)
    phi = rng.uniform(0.0, 2 * np.pi, n)
    return r * np.cos(phi), r * np.sin(phi)
