"""Models that learned nothing, as NumPy adapters with the trained models' interface (see
`replication.evaluation.adapters`): `Zero` predicts 0 for everything, `Diverging` predicts accelerations and
time derivatives that blow up in finite time (any rollout reaches inf within a few steps)."""
from __future__ import annotations

import numpy as np

BLOW = 1e3


class Zero:
    def __init__(self, spec):
        self.spec, self.kind = spec, spec.kind

    def acceleration(self, q, qdot, extra=None):
        return np.zeros_like(np.asarray(q, np.float64))

    def time_derivative(self, x, y, extra=None):
        return np.zeros_like(np.asarray(y, np.float64)), np.zeros_like(np.asarray(x, np.float64))

    def inverse_dynamics(self, q, qdot, qddot):
        return np.zeros_like(np.asarray(q, np.float64))

    def mass_matrix(self, q):
        q = np.asarray(q, np.float64)
        return np.zeros(q.shape + q.shape[-1:])

    def velocity_hessian(self, q, qdot, extra=None):
        return self.mass_matrix(q)

    def acceleration_info(self, q, qdot, extra=None):
        return self.acceleration(q, qdot, extra), 0


class Diverging(Zero):
    """qdd = BLOW (1 + qdot^2): qdot = tan(BLOW t) from rest, infinite after pi / (2 BLOW) time units."""

    def acceleration(self, q, qdot, extra=None):
        v = np.asarray(qdot, np.float64)
        with np.errstate(over="ignore", invalid="ignore"):
            return BLOW * (1.0 + v * v)

    def time_derivative(self, x, y, extra=None):
        return self.acceleration(x, y), self.acceleration(y, x)

    def inverse_dynamics(self, q, qdot, qddot):
        return self.acceleration(q, qdot)

    def mass_matrix(self, q):
        q = np.asarray(q, np.float64)
        return -np.broadcast_to(np.eye(q.shape[-1]), q.shape + q.shape[-1:]).copy()


class NoisyOracle(Zero):
    """The true acceleration of ``system`` plus ``noise`` x N(0, 1): a model that has learned its task
    (held-out L1 about 0.8 noise per component), for checking that a verdict can be reached at all."""

    def __init__(self, spec, system, noise=0.01, seed=0):
        super().__init__(spec)
        self.system, self.noise, self.rng = system, noise, np.random.default_rng(seed)

    def acceleration(self, q, qdot, extra=None):
        a = self.system.acceleration(np.asarray(q, np.float64), np.asarray(qdot, np.float64))
        return a + self.noise * self.rng.standard_normal(a.shape)


class FieldOracle(Zero):
    """The relativistic particle's true q-double-dot, the field g read from the model's extra input, or with
    g zeroed (``use_field=False``): a model whose relativistic input path is broken. On (q, qdot) its time
    derivative is (qdot, q-double-dot), as an HNN on (q, qdot) predicts it."""

    def __init__(self, spec, system, use_field=True):
        super().__init__(spec)
        self.system, self.use_field = system, use_field

    def acceleration(self, q, qdot, extra=None):
        q, qdot = np.asarray(q, np.float64), np.asarray(qdot, np.float64)
        g = np.asarray(extra, np.float64)[..., 0] if self.use_field and extra is not None else np.zeros(q.shape[:-1])
        return self.system.acceleration(q, qdot, backend="numpy", g=g)

    def time_derivative(self, x, y, extra=None):
        return np.asarray(y, np.float64), self.acceleration(x, y, extra)
