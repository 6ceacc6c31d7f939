"""Lagrangian graph network on a periodic 1D grid (JAX): L = sum_i density(q_nb(i), qdot_nb(i)).

q, qdot (..., n) with any n at call time (a model trained at n = 10 runs at n = 100). The density MLP
sees [q_{i-r..i+r}, qdot_{i-r..i+r}] (2(2r+1) inputs): the neighbours `models.graph.periodic_neighbours`
names, taken by rolls.
Accelerations by spec.own.formulation:
  "dense":  full n x n Hessian (forward-over-reverse) + solve with the counted pinv fallback (`lnn`).
  "paper":  the original code's full Hessian, full mixed Jacobian and pinv (`lnn`, "paper").
  "banded" (alias "fast"): the velocity Hessian is cyclic-banded (half-bandwidth 2r); `LGN` takes its band
            from each node's hand-written MLP derivatives (`LGN._banded_terms`, 2r+2 tangents per node),
            any other L_fn from one reverse pass pushed forward along <= 8r+1 coloured tangents plus the
            one mixed-term tangent (`banded_terms`, `models.graph.band_coloring`), and the system is
            solved in O(n) by `models.jax.banded`. Samples whose solve is not finite take pinv of the dense
            matrix and are counted. Grids with n < 4r + 1 use the dense path.
Mirrored line for line by `models.torch.lgn`. Neighbours are gathered by rolls, not index arrays: in a
training step the derivative of an index gather is a scatter-add, which XLA runs slowly on a CPU (the
3x64 LGN's step at batch 32 went from 34 ms to 4.8 ms with the hand-written band, one thread).
"""
from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import lax

from lagbench.models.graph import (
    band_coloring,
    band_columns,
    band_from_colours,
    band_sum,
    banded_supported,
    cyclic_band_layout,
    identity_band,
)
from lagbench.models.jax.banded import solve_cyclic_banded
from lagbench.models.jax.base import Model
from lagbench.models.jax.lnn import euler_lagrange_info, pinv_solve
from lagbench.models.jax.mlp import input_scale, mlp, mlp_input, wrap_angles
from lagbench.models.jax.mlp_derivatives import input_grad_and_tangent_hessian


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


def dense_from_band(band):
    """The (B, n, n) matrix of a cyclic band (B, n, 2w+1) (n >= 2w+1: no two band entries share a place)."""
    bsz, n, width = band.shape
    cols = band_columns(n, width)
    rows = np.broadcast_to(np.arange(n)[:, None], cols.shape)
    return jnp.zeros((bsz, n, n), band.dtype).at[:, rows, cols].set(band)


def _banded_solve_info(band, rhs, r):
    """Flat band (B, n, 4r+1), rhs (B, n): (x (B, n), n_fallback); samples whose solve is not finite take
    pinv of the dense matrix (counted), solved again on an identity band first so that no NaN reaches the
    gradient."""
    n = rhs.shape[-1]
    layout = cyclic_band_layout(n, r)
    x = solve_cyclic_banded(band, rhs, layout)
    bad = ~jnp.all(jnp.isfinite(lax.stop_gradient(x)), axis=-1)

    def fallback():
        safe = jnp.where(bad[:, None, None], jnp.asarray(identity_band(n, r), band.dtype), band)
        x_safe = solve_cyclic_banded(safe, rhs, layout)
        return jnp.where(bad[:, None], pinv_solve(dense_from_band(band), rhs), x_safe)
    x = lax.cond(jnp.any(bad), fallback, lambda: x)
    return x, jnp.sum(bad)


def banded_euler_lagrange_info(L_fn, q, qdot, r):
    """(qddot (..., n), n_fallback) by the banded path for any L_fn (its band from `banded_terms`); see the
    module doc. `LGN` solves its own hand-differentiated band the same way."""
    n = q.shape[-1]
    x, n_bad = _banded_solve_info(*banded_terms(L_fn, q.reshape(-1, n), qdot.reshape(-1, n), r), r)
    return x.reshape(q.shape), n_bad


def _neighbours(x, r):
    """x (..., n) -> (..., n, 2r+1): x at nodes i-r .. i+r (mod n), as `periodic_neighbours` indexes them,
    by rolls (whose derivative is a roll; an index gather's is a scatter-add, slow in XLA on a CPU)."""
    return jnp.stack([jnp.roll(x, r - a, axis=-1) for a in range(2 * r + 1)], axis=-1)


class LGN(Model):
    def _lagrangian(self, q, qdot):
        x = mlp_input(self.spec, [_neighbours(wrap_angles(self.spec, q), self.spec.own.radius),
                                  _neighbours(qdot, self.spec.own.radius)])
        return jnp.sum(mlp(self.params, x, self.spec)[..., 0], axis=-1)

    def _banded_terms(self, q, qdot):
        """On flat (B, n): (band (B, n, 4r+1), rhs = dL/dq - J qdot (B, n)), as `banded_terms` gives them,
        from the hand-written MLP derivatives (`models.jax.mlp_derivatives`). Node i's density sees
        x_i = scale * [q_nb(i), qdot_nb(i)] (k = 2r+1 neighbours i+a-r); its MLP gradient g_i and its Gram
        G_i (tangents: s_qd[a] e_(k+a) for each a, and s_q * qdot_nb(i) in the q slots) give every term:
        node i adds G_i[a, b] to H[i+a-r, i+b-r] (band column 2r+b-a), G_i[a, k] to (J qdot)[i+a-r] and
        s_q[b] g_i[b] to dL/dq[i+b-r]. Rolling slot a's terms by a-r moves them all into place."""
        spec, (bsz, n), r = self.spec, q.shape, self.spec.own.radius
        k = 2 * r + 1
        qdot_nb = _neighbours(qdot, r)
        x = mlp_input(spec, [_neighbours(wrap_angles(spec, q), r), qdot_nb]).reshape(bsz * n, 2 * k)
        scale = input_scale(spec, 2 * k, x.dtype)
        s_q, s_qd = scale[:k], scale[k:]
        rows = jnp.concatenate([jnp.zeros((k, k), x.dtype), jnp.diag(s_qd)], -1)
        mixed = jnp.concatenate([qdot_nb.reshape(bsz * n, k) * s_q, jnp.zeros((bsz * n, k), x.dtype)], -1)
        tangents = jnp.concatenate([jnp.broadcast_to(rows, (bsz * n, k, 2 * k)), mixed[:, None, :]], 1)
        g, gram = input_grad_and_tangent_hessian(self.params, x, tangents, spec, rows=k)
        g = jnp.concatenate([(g[:, :k] * s_q).reshape(bsz, n, k, 1), gram.reshape(bsz, n, k, k + 1)], -1)
        moved = jnp.stack([jnp.roll(g[:, :, a], a - r, axis=1) for a in range(k)], 2)  # [j, a]: node j-a+r's slot a
        band = moved[..., 1:k + 1].reshape(bsz, n, k * k) @ jnp.asarray(band_sum(r), x.dtype)
        return band, moved[..., 0].sum(-1) - moved[..., k + 1].sum(-1)

    @eqx.filter_jit
    def lagrangian(self, q, qdot, extra=None):
        """L (...,) for q, qdot (..., n)."""
        self._check_state(q, qdot, extra, width=q.shape[-1])
        return self._lagrangian(q, qdot)

    @eqx.filter_jit
    def acceleration_info(self, q, qdot, extra=None):
        """(qddot (..., n), n_fallback) with spec.own.formulation."""
        self._check_state(q, qdot, extra, width=q.shape[-1])
        form, n, r = self.spec.own.formulation, q.shape[-1], self.spec.own.radius
        if form in ("banded", "fast") and banded_supported(n, r):
            band, rhs = self._banded_terms(q.reshape(-1, n), qdot.reshape(-1, n))
            x, n_bad = _banded_solve_info(band, rhs, r)
            return x.reshape(q.shape), n_bad
        return euler_lagrange_info(self._lagrangian, q, qdot, "paper" if form == "paper" else "fast")

    def acceleration(self, q, qdot, extra=None):
        """qddot (..., n)."""
        return self.acceleration_info(q, qdot, extra)[0]
