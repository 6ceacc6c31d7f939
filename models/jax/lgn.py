"""Lagrangian graph network on a periodic 1D grid (JAX): L = sum_i density(q_nb(i), qdot_nb(i)).

q, qdot (..., n) with any n at call time (a model trained at n = 10 runs at n = 100). The density MLP
sees [q_{i-r..i+r}, qdot_{i-r..i+r}] (2(2r+1) inputs) gathered by `models.graph.periodic_neighbours`.
Accelerations by spec.formulation:
  "dense":  full n x n Hessian (forward-over-reverse) + solve with the counted pinv fallback (`lnn`).
  "paper":  the original code's full Hessian, full mixed Jacobian and pinv (`lnn`, "paper").
  "banded" (alias "fast"): the velocity Hessian is cyclic-banded (half-bandwidth 2r); its band comes from
            one reverse pass pushed forward along <= 8r+1 coloured tangents plus the one mixed-term
            tangent (`models.graph.band_coloring`), and the system is solved in O(n) by
            `models.jax.banded`. Samples whose solve is not finite take pinv of the dense Hessian and are
            counted. Grids with n < 4r + 1 use the dense path.
"""
from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import lax

from models.graph import (
    band_coloring,
    band_from_colours,
    banded_supported,
    cyclic_band_layout,
    periodic_neighbours,
)
from models.jax.banded import solve_cyclic_banded
from models.jax.base import Model
from models.jax.blocking import in_row_blocks
from models.jax.lnn import euler_lagrange_info, fast_terms, pinv_solve
from models.jax.mlp import mlp, mlp_input, wrap_angles


def banded_terms(L_fn, q, qdot, r):
    """On flat (B, n): (band (B, n, 4r+1), rhs = dL/dq - J qdot (B, n)) by coloured forward-over-reverse."""
    n = q.shape[-1]
    colour, n_col = band_coloring(n, r)
    grads = jax.grad(lambda a, b: jnp.sum(L_fn(a, b)), argnums=(0, 1))
    onehot = jnp.asarray(colour[None, :] == jnp.arange(n_col)[:, None], dtype=q.dtype)
    t_q = jnp.concatenate([jnp.zeros((n_col, *q.shape), q.dtype), qdot[None]])
    t_qdot = jnp.concatenate([jnp.broadcast_to(onehot[:, None, :], (n_col, *q.shape)), jnp.zeros_like(qdot)[None]])
    (g_q, _), (_, dg_qdot) = jax.vmap(lambda a, b: jax.jvp(grads, (q, qdot), (a, b)))(t_q, t_qdot)
    col, row = band_from_colours(n, r)
    return jnp.moveaxis(dg_qdot[:n_col], 0, 1)[:, col, row], g_q[0] - dg_qdot[n_col]


def _identity_band(n, r):
    return np.eye(1, 4 * r + 1, 2 * r)[0][None, :].repeat(n, 0)


def banded_euler_lagrange_info(L_fn, q, qdot, r):
    """(qddot (..., n), n_fallback) by the banded path; see the module doc."""
    n, batch = q.shape[-1], q.shape[:-1]
    qf, qdf = q.reshape(-1, n), qdot.reshape(-1, n)
    band, rhs = banded_terms(L_fn, qf, qdf, r)
    layout = cyclic_band_layout(n, r)
    x = solve_cyclic_banded(band, rhs, layout)
    bad = ~jnp.all(jnp.isfinite(lax.stop_gradient(x)), axis=-1)

    def fallback():
        safe = jnp.where(bad[:, None, None], jnp.asarray(_identity_band(n, r), band.dtype), band)
        x_safe = solve_cyclic_banded(safe, rhs, layout)
        # the dense terms in cache-sized row blocks: XLA reserves this branch's memory on every call
        dense = in_row_blocks(lambda a, b: fast_terms(L_fn, a, b), (qf, qdf), n + 1)
        return jnp.where(bad[:, None], pinv_solve(*dense), x_safe)
    x = lax.cond(jnp.any(bad), fallback, lambda: x)
    return x.reshape(*batch, n), jnp.sum(bad)


class LGN(Model):
    def _lagrangian(self, q, qdot):
        nb = periodic_neighbours(q.shape[-1], self.spec.lgn_radius)
        x = mlp_input(self.spec, [wrap_angles(self.spec, q)[..., nb], qdot[..., nb]])
        return jnp.sum(mlp(self.params, x, self.spec)[..., 0], axis=-1)

    @eqx.filter_jit
    def lagrangian(self, q, qdot, extra=None):
        """L (...,) for q, qdot (..., n)."""
        self._check_state(q, qdot, extra, width=q.shape[-1])
        return self._lagrangian(q, qdot)

    @eqx.filter_jit
    def acceleration_info(self, q, qdot, extra=None):
        """(qddot (..., n), n_fallback) with spec.formulation."""
        self._check_state(q, qdot, extra, width=q.shape[-1])
        form, n, r = self.spec.formulation, q.shape[-1], self.spec.lgn_radius
        if form in ("banded", "fast") and banded_supported(n, r):
            return banded_euler_lagrange_info(self._lagrangian, q, qdot, r)
        return euler_lagrange_info(self._lagrangian, q, qdot, "paper" if form == "paper" else "fast")

    def acceleration(self, q, qdot, extra=None):
        """qddot (..., n)."""
        return self.acceleration_info(q, qdot, extra)[0]
