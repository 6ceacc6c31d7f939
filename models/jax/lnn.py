"""Euler-Lagrange accelerations of any scalar L(q, qdot), and the LNN model (JAX).

`euler_lagrange_info(L_fn, q, qdot, formulation="fast", extra=None) -> (qddot, n_fallback)`
  L_fn(q, qdot[, extra]) -> (...,) for q, qdot (..., d), acting on each sample independently.
  q, qdot (..., d); extra (..., e) or None. qddot (..., d); n_fallback an int scalar array.
  "paper": per sample, q'' = pinv(H) (dL/dq - J qdot), H = jax.hessian(L, 1), J = the full mixed
           Jacobian jax.jacobian(jax.jacobian(L, 1), 0), pinv by SVD with rtol = 10 d eps
           (`models.numerics.pinv_rtol`); n_fallback = 0.
  "fast":  one reverse pass for (dL/dq, dL/dqdot) summed over the batch, pushed forward along d + 1
           tangents at once (the d unit vectors in qdot -> the Hessian columns; qdot in q -> the mixed
           term J qdot as ONE Jacobian-vector product), then a linear solve. Fallback: where the
           reciprocal 1-norm condition number of H is below `models.numerics.rcond_min` (or the inverse
           is not finite) the sample takes the paper's pinv result and is counted in n_fallback.
           Indefinite but well-conditioned H are solved exactly (pinv would give the same).
`euler_lagrange(...)` returns qddot only; `velocity_hessian(L_fn, q, qdot, extra)` -> (..., d, d).
Large batches are computed in cache-sized row blocks (`models.jax.blocking`, the plan of
`models.row_blocks`). PyTorch's compiled calls use the same blocks (`models.torch.compiled`); eager
PyTorch gained nothing reliable from them.
Mirrored line for line by `models.torch.lnn`; in both, `LNN`'s own fast terms come from the hand-written
MLP derivatives (`models.jax.mlp_derivatives`), the generic `fast_terms` serves any other L_fn.
"""
from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import lax

from lagbench.models.jax.base import Model
from lagbench.models.jax.blocking import in_row_blocks
from lagbench.models.jax.mlp import input_scale, mlp, mlp_input, q_features, q_features_jvp, q_features_vjp
from lagbench.models.jax.mlp_derivatives import input_grad_and_tangent_hessian
from lagbench.models.lorentz import lorentz_slopes, velocity_parts
from lagbench.models.numerics import pinv_rtol, rcond_min


def _call(L_fn, q, qdot, extra):
    return L_fn(q, qdot) if extra is None else L_fn(q, qdot, extra)


def _flat(x, d):
    return None if x is None else x.reshape(-1, x.shape[-1] if d is None else d)


def fast_terms(L_fn, q, qdot, extra=None):
    """On flat (B, d): (H (B, d, d), rhs = dL/dq - J qdot (B, d)), by forward-over-reverse."""
    d = q.shape[-1]
    grads = jax.grad(lambda a, b: jnp.sum(_call(L_fn, a, b, extra)), argnums=(0, 1))
    eye = jnp.broadcast_to(jnp.eye(d, dtype=q.dtype)[:, None, :], (d, *q.shape))
    t_q = jnp.concatenate([jnp.zeros((d, *q.shape), q.dtype), qdot[None]])
    t_qdot = jnp.concatenate([eye, jnp.zeros_like(qdot)[None]])
    (g_q, _), (_, dg_qdot) = jax.vmap(lambda a, b: jax.jvp(grads, (q, qdot), (a, b)))(t_q, t_qdot)
    return jnp.moveaxis(dg_qdot[:d], 0, -1), g_q[0] - dg_qdot[d]


def paper_terms(L_fn, q, qdot, extra=None):
    """On flat (B, d), per sample: (H (B, d, d), rhs = dL/dq - J qdot (B, d)) with full Jacobians."""
    def one(q1, qd1, e1):
        f = lambda a, b: _call(L_fn, a, b, e1)  # noqa: E731
        hess = jax.hessian(f, 1)(q1, qd1)
        mixed = jax.jacobian(jax.jacobian(f, 1), 0)(q1, qd1)
        return hess, jax.grad(f, 0)(q1, qd1) - mixed @ qd1
    if extra is None:
        return jax.vmap(lambda a, b: one(a, b, None))(q, qdot)
    return jax.vmap(one)(q, qdot, extra)


def pinv_solve(hess, rhs):
    """pinv(H) rhs per sample, H (B, d, d), rhs (B, d), rtol = 10 d eps."""
    rtol = pinv_rtol(str(hess.dtype), hess.shape[-1])
    return (jnp.linalg.pinv(hess, rtol=rtol) @ rhs[..., None])[..., 0]


def _norm1(a):
    return jnp.max(jnp.sum(jnp.abs(a), axis=-2), axis=-1)


def solve_with_fallback(hess, rhs):
    """(H^-1 rhs (B, d), n_fallback): pinv where H is singular/ill-conditioned, counted."""
    d = hess.shape[-1]
    h = lax.stop_gradient(hess)
    rcond = 1.0 / (_norm1(h) * _norm1(jnp.linalg.inv(h)))
    bad = ~(jnp.isfinite(rcond) & (rcond >= rcond_min(str(hess.dtype), d)))
    safe = jnp.where(bad[:, None, None], jnp.eye(d, dtype=hess.dtype), hess)
    x = jnp.linalg.solve(safe, rhs[..., None])[..., 0]
    x = lax.cond(jnp.any(bad), lambda: jnp.where(bad[:, None], pinv_solve(hess, rhs), x), lambda: x)
    return x, jnp.sum(bad)


def euler_lagrange_info(L_fn, q, qdot, formulation="fast", extra=None):
    """(qddot (..., d), n_fallback) from the Euler-Lagrange equation of L_fn; see the module doc."""
    d, batch = q.shape[-1], q.shape[:-1]
    qf, qdf, ef = _flat(q, d), _flat(qdot, d), _flat(extra, None)
    if formulation == "paper":
        hess, rhs = in_row_blocks(lambda a, b, e: paper_terms(L_fn, a, b, e), (qf, qdf, ef), d + 1)
        return pinv_solve(hess, rhs).reshape(*batch, d), jnp.zeros((), jnp.int64)
    if formulation != "fast":
        raise ValueError(f"unknown formulation {formulation!r}; valid: fast, paper")
    hess, rhs = in_row_blocks(lambda a, b, e: fast_terms(L_fn, a, b, e), (qf, qdf, ef), d + 1)
    x, n_bad = solve_with_fallback(hess, rhs)
    return x.reshape(*batch, d), n_bad


def euler_lagrange(L_fn, q, qdot, formulation="fast", extra=None):
    """qddot (..., d) from the Euler-Lagrange equation of L_fn (fallbacks counted but dropped)."""
    return euler_lagrange_info(L_fn, q, qdot, formulation, extra)[0]


def velocity_hessian(L_fn, q, qdot, extra=None):
    """d^2 L / dqdot^2, (..., d, d), by forward-over-reverse."""
    d = q.shape[-1]
    hess, _ = fast_terms(L_fn, _flat(q, d), _flat(qdot, d), _flat(extra, None))
    return hess.reshape(*q.shape, d)


def _scaled_q_part(x, f, nq):
    """x's q slots with their value s_q f(q) (exactly x's) but the q-derivative df/dq, for
    `Lnn.scale_q_before_grad` (`models.kinds`): the original LNN code forms q / 10 before jax.grad, so its dL/dq and mixed
    term are those in the scaled q, without the factor s_q. f - stop_gradient(f) is exactly 0 and carries f's
    derivatives."""
    return lax.stop_gradient(x[..., :nq]) + (f - lax.stop_gradient(f))


class LNN(Model):
    """L = MLP([f(q), qdot, extra]) (f: `q_features`), or with spec.own.even_velocity its average over qdot and
    -qdot; q, qdot (..., dof), extra (..., extra_inputs) or None.

    The fast formulation and velocity_hessian differentiate the model's own MLP by hand
    (`models.jax.mlp_derivatives`): same values as `fast_terms(self._lagrangian, ...)`, fewer FLOPs
    (XLA's forward-over-reverse also pushes the d + 1 tangents back through the network)."""

    def _lagrangian(self, q, qdot, extra=None):
        if self.spec.own.even_velocity:   # (N(q, qdot) + N(q, -qdot)) / 2
            return (self._network(q, qdot, extra) + self._network(q, -qdot, extra)) / 2
        return self._network(q, qdot, extra)

    def _network(self, q, qdot, extra=None):
        """N(q, qdot), the MLP's output."""
        spec, f = self.spec, q_features(self.spec, q)
        x = mlp_input(spec, [f, *velocity_parts(spec, qdot), *self._parts(extra)])
        if spec.own.scale_q_before_grad:   # the original's convention: q-derivatives in the scaled x_q = s_q f(q)
            x = jnp.concatenate([_scaled_q_part(x, f, spec.q_width()), x[..., spec.q_width():]], axis=-1)
        return mlp(self.params, x, spec)[..., 0]

    def _fast_terms(self, q, qdot, extra=None):
        """On flat (B, d): (H (B, d, d), rhs = dL/dq - J qdot (B, d)), as `fast_terms` gives them. With
        spec.own.even_velocity, L = (N(q, qdot) + N(q, -qdot)) / 2 and both terms are the average of N's at
        (q, qdot) and (q, -qdot) (the sign flips of the mixed term cancel: J_L qdot = (J_N(+) - J_N(-)) qdot / 2),
        from one pass over the doubled batch."""
        if not self.spec.own.even_velocity:
            return self._network_terms(q, qdot, extra)
        n = q.shape[0]
        hess, rhs = self._network_terms(jnp.concatenate([q, q]), jnp.concatenate([qdot, -qdot]),
                                        None if extra is None else jnp.concatenate([extra, extra]))
        return (hess[:n] + hess[n:]) / 2, (rhs[:n] + rhs[n:]) / 2

    def _network_terms(self, q, qdot, extra=None):
        """N's (H, dL/dq - J qdot) on flat (B, d), N the MLP.
        MLP input x = scale * [f(q), qdot, extra], f the q part (`q_features`, p = q_width - d slots wider with
        periodic coordinates; extra is not differentiated): tangents s_qd[k] e_(p+d+k) give the Hessian columns,
        s_q * (df/dq) qdot in the q part's slots the mixed term J qdot, and dL/dq = (df/dq)^T (s_q g_q) (f has
        no qdot in it: H needs none of its curvature). With the Lorentz factor, x = scale * [f(q), qdot,
        gamma(qdot), extra]: column k also has s_g[k] gamma'(qdot_k) in the gamma slot k, and H gains the
        curvature of the feature itself, diag(dL/dx_gamma_k s_g[k] gamma''). With spec.own.scale_q_before_grad both q-side
        factors s_q are 1: the q-derivatives are taken in the scaled x_q, as the original code does."""
        spec, (n, d) = self.spec, q.shape
        x = mlp_input(spec, [q_features(spec, q), *velocity_parts(spec, qdot), *self._parts(extra)])
        scale = input_scale(spec, x.shape[-1], x.dtype)
        nq = spec.q_width()
        s_q, s_qd, s_g = scale[:nq], scale[nq:nq + d], scale[nq + d:nq + 2 * d]
        if spec.own.scale_q_before_grad:   # q-derivatives in the scaled x_q (the original's convention): no factor s_q
            s_q = jnp.ones_like(s_q)
        tangents = jnp.zeros((n, d + 1, x.shape[-1]), dtype=x.dtype)
        tangents = tangents.at[:, :d, nq:nq + d].set(jnp.diag(s_qd))
        tangents = tangents.at[:, d, :nq].set(q_features_jvp(spec, q, qdot) * s_q)
        if spec.lorentz_factor:
            slope, curve = lorentz_slopes(qdot)
            k = jnp.arange(d)
            tangents = tangents.at[:, k, nq + d + k].set(slope * s_g)
        g, gram = input_grad_and_tangent_hessian(self.params, x, tangents, spec, rows=d)
        hess = gram[:, :d, :d]
        if spec.lorentz_factor:
            hess = hess + jnp.eye(d, dtype=x.dtype) * (g[:, nq + d:nq + 2 * d] * s_g * curve)[:, None, :]
        return hess, q_features_vjp(spec, q, g[:, :nq] * s_q) - gram[:, :d, d]

    def _blocked_terms(self, q, qdot, extra):
        """`_fast_terms` on the flattened batch, in cache-sized row blocks (`models.jax.blocking`)."""
        d = q.shape[-1]
        return in_row_blocks(self._fast_terms, (_flat(q, d), _flat(qdot, d), _flat(extra, None)), d + 1)

    @eqx.filter_jit
    def lagrangian(self, q, qdot, extra=None):
        """L (...,)."""
        self._check_state(q, qdot, extra)
        return self._lagrangian(q, qdot, extra)

    @eqx.filter_jit
    def velocity_hessian(self, q, qdot, extra=None):
        """(..., dof, dof)."""
        self._check_state(q, qdot, extra)
        d, extra = q.shape[-1], extra if self.spec.extra_inputs else None
        hess, _ = self._blocked_terms(q, qdot, extra)
        return hess.reshape(*q.shape, d)

    @eqx.filter_jit
    def acceleration_info(self, q, qdot, extra=None):
        """(qddot (..., dof), n_fallback) with spec.own.formulation."""
        self._check_state(q, qdot, extra)
        extra = extra if self.spec.extra_inputs else None
        if self.spec.own.formulation != "fast":
            return euler_lagrange_info(self._lagrangian, q, qdot, self.spec.own.formulation, extra)
        d = q.shape[-1]
        hess, rhs = self._blocked_terms(q, qdot, extra)
        if self.spec.dissipation:   # Rayleigh D = 1/2 sum b qdot^2 against L's orientation: -sign(tr H) b qdot
            side = jnp.sign(jnp.trace(hess, axis1=-2, axis2=-1))[:, None]
            rhs = rhs - side * jax.nn.softplus(self.params["dissipation.raw"]) * _flat(qdot, d)
        x, n_bad = solve_with_fallback(hess, rhs)
        return x.reshape(*q.shape[:-1], d), n_bad

    def acceleration(self, q, qdot, extra=None):
        """qddot (..., dof)."""
        return self.acceleration_info(q, qdot, extra)[0]
