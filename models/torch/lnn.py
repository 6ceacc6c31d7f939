"""Euler-Lagrange accelerations of any scalar L(q, qdot), and the LNN model (PyTorch, torch.func).

Mirrors `models.jax.lnn` line for line (see its docstring for the formulations and the fallback), except
that `LNN`'s own fast terms come from the hand-written MLP derivatives (`models.torch.mlp_derivatives`),
that a traced paper formulation takes one full Hessian instead of three transforms (`paper_terms`), and
that the solve at inference reuses the inverse of its condition estimate (`solve_with_fallback`).
`euler_lagrange_info(L_fn, q, qdot, formulation="fast", extra=None) -> (qddot (..., d), n_fallback)`,
`euler_lagrange(...) -> qddot`, `velocity_hessian(L_fn, q, qdot, extra) -> (..., d, d)`.
Outputs stay differentiable w.r.t. tensors L_fn closes over (the nn.Parameters): loss.backward() works.
What runs differently in a captured graph (make_fx, torch.export) or under vmap is chosen by
`models.torch.export_paths`.
"""
from __future__ import annotations

import torch
from torch.func import grad, hessian, jacfwd, jacrev, jvp, vmap

from lagbench.models.lorentz import lorentz_slopes, velocity_parts
from lagbench.models.numerics import pinv_rtol, rcond_min
from lagbench.models.torch.base import Model
from lagbench.models.torch.export_paths import pick, replace_bad_rows
from lagbench.models.torch.mlp import input_scale, mlp, mlp_input, q_features, q_features_jvp, q_features_vjp
from lagbench.models.torch.mlp_derivatives import input_grad_and_tangent_hessian


def _dtype_name(x) -> str:
    return str(x.dtype).removeprefix("torch.")


def _call(L_fn, q, qdot, extra):
    return L_fn(q, qdot) if extra is None else L_fn(q, qdot, extra)


def _flat(x, d):
    return None if x is None else x.reshape(-1, x.shape[-1] if d is None else d)


def fast_terms(L_fn, q, qdot, extra=None):
    """On flat (B, d): (H (B, d, d), rhs = dL/dq - J qdot (B, d)), by forward-over-reverse."""
    d = q.shape[-1]
    grads = grad(lambda a, b: torch.sum(_call(L_fn, a, b, extra)), argnums=(0, 1))
    eye = torch.eye(d, dtype=q.dtype, device=q.device)[:, None, :].expand(d, *q.shape)
    t_q = torch.cat([torch.zeros((d, *q.shape), dtype=q.dtype, device=q.device), qdot[None]])
    t_qdot = torch.cat([eye, torch.zeros_like(qdot)[None]])
    (g_q, _), (_, dg_qdot) = vmap(lambda a, b: jvp(grads, (q, qdot), (a, b)))(t_q, t_qdot)
    return torch.movedim(dg_qdot[:d], 0, -1), g_q[0] - dg_qdot[d]


def paper_terms(L_fn, q, qdot, extra=None):
    """On flat (B, d), per sample: (H (B, d, d), rhs = dL/dq - J qdot (B, d)) with full Jacobians.

    Eager: the original code's three transforms (hessian(L, 1), jacrev(jacrev(L, 1), 0), grad(L, 0)), as
    the JAX mirror. Traced by make_fx (`models.torch.compiled.trace_flat`, the speed study's "traced"
    mode; chosen by `models.torch.export_paths.pick`): H and J as blocks of one full Hessian of L in x =
    [q, qdot], forward over the one reverse pass that also gives dL/dq. Same values (float32: 1e-6
    relative). Measured (3 x 600 softplus, batch 4096, float32, 2 cores, interleaved rounds; traced): 6.3k
    -> 8.2k samples/s at d = 2, 1.02k -> 1.03k at d = 16; 3 x 128, d = 2: batch 1 2.4k -> 3.0k, float64
    batch 256 21.6k -> 24.9k. Eager the one Hessian ran 2.1x (d = 2) to 2.6x (d = 16) slower at 3 x 600,
    batch 4096 (its unfused 2d-tangent intermediates), so eager keeps the three. JAX's compiled program
    costs the same either way (XLA merges the three transforms' shared passes)."""
    d = q.shape[-1]

    def one_hessian(q1, qd1, e1):
        g = grad(lambda x: _call(L_fn, x[:d], x[d:], e1))

        def grad_and_aux(x):  # one reverse pass: its value is both the output and the aux (dL/dq)
            gx = g(x)
            return gx, gx
        full, g1 = jacfwd(grad_and_aux, has_aux=True)(torch.cat([q1, qd1]))
        return full[d:, d:], g1[:d] - full[d:, :d] @ qd1

    def three(q1, qd1, e1):
        f = lambda a, b: _call(L_fn, a, b, e1)  # noqa: E731
        hess = hessian(f, 1)(q1, qd1)
        mixed = jacrev(jacrev(f, 1), 0)(q1, qd1)
        return hess, grad(f, 0)(q1, qd1) - mixed @ qd1
    one = pick(three, traced=one_hessian)
    if extra is None:
        return vmap(lambda a, b: one(a, b, None))(q, qdot)
    return vmap(one)(q, qdot, extra)


def pinv_solve(hess, rhs, by_svd=False):
    """pinv(H) rhs per sample, H (B, d, d), rhs (B, d), rtol = 10 d eps. by_svd: the same from
    torch.linalg.svd by hand (singular values <= rtol * largest dropped, as pinv does): no gradient
    (1/s of a dropped value is inf), but it exports for a data-dependent B, which pinv does not."""
    rtol = pinv_rtol(_dtype_name(hess), hess.shape[-1])
    # torch's SVD raises on non-finite input where JAX returns NaN: give NaN for those samples too
    finite = torch.isfinite(hess).flatten(-2).all(-1)
    safe = torch.where(finite[..., None, None], hess, torch.zeros_like(hess))
    if by_svd:
        u, sv, vh = torch.linalg.svd(safe)
        inv = torch.where(sv > rtol * sv[..., :1], 1.0 / sv, torch.zeros_like(sv))
        x = (vh.mT @ (inv[..., None] * (u.mT @ rhs[..., None])))[..., 0]
    else:
        x = (torch.linalg.pinv(safe, rtol=rtol) @ rhs[..., None])[..., 0]
    return torch.where(finite[..., None], x, torch.full_like(x, float("nan")))


def _norm1(a):
    return torch.amax(torch.sum(torch.abs(a), dim=-2), dim=-1)


def small_inverse(h):
    """(inverse (B, d, d), info (B,), nonzero where singular): closed form for d <= 2 (no LAPACK call:
    at batch 1 the call, not the arithmetic, is the cost), torch.linalg.inv_ex otherwise."""
    d = h.shape[-1]
    if d == 1:
        return 1.0 / h, (h[..., 0, 0] == 0).to(torch.int32)
    if d == 2:
        a, b, c, e = h[..., 0, 0], h[..., 0, 1], h[..., 1, 0], h[..., 1, 1]
        det = a * e - b * c
        adj = torch.stack([torch.stack([e, -b], -1), torch.stack([-c, a], -1)], -2)
        return adj / det[..., None, None], (det == 0).to(torch.int32)
    return torch.linalg.inv_ex(h)


def solve_with_fallback(hess, rhs):
    """(H^-1 rhs (B, d), n_fallback): pinv where H is singular/ill-conditioned, counted. The bad samples
    take pinv through `models.torch.export_paths.replace_bad_rows` (eager: only if there are any; in a
    captured graph or under vmap without a Python branch on data). Without gradients (inference) the
    well-conditioned samples use the inverse the condition estimate already needed (`small_inverse`)
    instead of a second, LU solve; with gradients they solve with H replaced by I on the bad samples, so
    that no inf reaches backward."""
    d = hess.shape[-1]
    h = hess.detach()
    inv, info = small_inverse(h)
    rcond = 1.0 / (_norm1(h) * _norm1(inv))
    bad = ~(torch.isfinite(rcond) & (rcond >= rcond_min(_dtype_name(hess), d)) & (info == 0))
    if torch.is_grad_enabled():
        safe = torch.where(bad[..., None, None], torch.eye(d, dtype=hess.dtype, device=hess.device), hess)
        x = torch.linalg.solve(safe, rhs[..., None])[..., 0]
    else:
        x = (inv @ rhs[..., None])[..., 0]
    return replace_bad_rows(x, bad, pinv_solve, hess, rhs), torch.sum(bad)


def euler_lagrange_info(L_fn, q, qdot, formulation="fast", extra=None):
    """(qddot (..., d), n_fallback) from the Euler-Lagrange equation of L_fn; see the module doc."""
    d, batch = q.shape[-1], q.shape[:-1]
    qf, qdf, ef = _flat(q, d), _flat(qdot, d), _flat(extra, None)
    if formulation == "paper":
        hess, rhs = paper_terms(L_fn, qf, qdf, ef)
        return pinv_solve(hess, rhs).reshape(*batch, d), torch.zeros((), dtype=torch.int64, device=q.device)
    if formulation != "fast":
        raise ValueError(f"unknown formulation {formulation!r}; valid: fast, paper")
    return _solved(*fast_terms(L_fn, qf, qdf, ef), batch)


def _solved(hess, rhs, batch):
    """The fast formulation's solve of flat (H (B, d, d), rhs (B, d)): (qddot (*batch, d), n_fallback)."""
    x, n_bad = solve_with_fallback(hess, rhs)
    return x.reshape(*batch, hess.shape[-1]), n_bad


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
    term are those in the scaled q, without the factor s_q. f - f.detach() is exactly 0 and carries f's
    derivatives (detach stops the gradient under torch.func's transforms too)."""
    return x[..., :nq].detach() + (f - f.detach())


class LNN(Model):
    """L = MLP([f(q), qdot, extra]) (f: `q_features`), or with spec.own.even_velocity its average over qdot and
    -qdot; q, qdot (..., dof), extra (..., extra_inputs) or None.

    The fast formulation and velocity_hessian differentiate the model's own MLP by hand
    (`models.torch.mlp_derivatives`): same values as `fast_terms(self._lagrangian, ...)`, faster."""

    @classmethod
    def stacks(cls, spec) -> bool:
        """The fast formulation's hand-written terms take stacked members; the paper's torch.func ones do not."""
        return spec.own.formulation == "fast"

    def _lagrangian(self, q, qdot, extra=None):
        if self.spec.own.even_velocity:   # (N(q, qdot) + N(q, -qdot)) / 2
            return (self._network(q, qdot, extra) + self._network(q, -qdot, extra)) / 2
        return self._network(q, qdot, extra)

    def _network(self, q, qdot, extra=None):
        """N(q, qdot), the MLP's output."""
        spec, f = self.spec, q_features(self.spec, q)
        x = mlp_input(spec, [f, *velocity_parts(spec, qdot), *self._parts(extra)])
        if spec.own.scale_q_before_grad:   # the original's convention: q-derivatives in the scaled x_q = s_q f(q)
            x = torch.cat([_scaled_q_part(x, f, spec.q_width()), x[..., spec.q_width():]], dim=-1)
        return mlp(self.params, x, spec)[..., 0]

    def _fast_terms(self, q, qdot, extra=None):
        """On flat (B, d): (H (B, d, d), rhs = dL/dq - J qdot (B, d)), as `fast_terms` gives them. With
        spec.own.even_velocity, L = (N(q, qdot) + N(q, -qdot)) / 2 and both terms are the average of N's at
        (q, qdot) and (q, -qdot) (the sign flips of the mixed term cancel: J_L qdot = (J_N(+) - J_N(-)) qdot / 2),
        from one pass over the doubled batch."""
        if not self.spec.own.even_velocity:
            return self._network_terms(q, qdot, extra)
        n = q.shape[-2]
        hess, rhs = self._network_terms(torch.cat([q, q], -2), torch.cat([qdot, -qdot], -2),
                                        None if extra is None else torch.cat([extra, extra], -2))
        return (hess[..., :n, :, :] + hess[..., n:, :, :]) / 2, (rhs[..., :n, :] + rhs[..., n:, :]) / 2

    def _network_terms(self, q, qdot, extra=None):
        """N's (H, dL/dq - J qdot) on flat (B, d), N the MLP.
        MLP input x = scale * [f(q), qdot, extra], f the q part (`q_features`, p = q_width - d slots wider with
        periodic coordinates; extra is not differentiated): tangents s_qd[k] e_(p+d+k) give the Hessian columns,
        s_q * (df/dq) qdot in the q part's slots the mixed term J qdot, and dL/dq = (df/dq)^T (s_q g_q) (f has
        no qdot in it: H needs none of its curvature). With the Lorentz factor, x = scale * [f(q), qdot,
        gamma(qdot), extra]: column k also has s_g[k] gamma'(qdot_k) in the gamma slot k, and H gains the
        curvature of the feature itself, diag(dL/dx_gamma_k s_g[k] gamma''). With spec.own.scale_q_before_grad both q-side
        factors s_q are 1: the q-derivatives are taken in the scaled x_q, as the original code does."""
        spec, lead, d = self.spec, q.shape[:-1], q.shape[-1]   # lead: (B,), or (K, B) for stacked members
        x = mlp_input(spec, [q_features(spec, q), *velocity_parts(spec, qdot), *self._parts(extra)])
        scale = input_scale(spec, x.shape[-1], x.dtype, x.device)
        nq = spec.q_width()
        s_q, s_qd, s_g = scale[:nq], scale[nq:nq + d], scale[nq + d:nq + 2 * d]
        if spec.own.scale_q_before_grad:   # q-derivatives in the scaled x_q (the original's convention): no factor s_q
            s_q = torch.ones_like(s_q)
        width = x.shape[-1]   # built out of place: under torch.func.vmap (stacked members) qdot is batched
        used = nq + (2 * d if spec.lorentz_factor else d)
        zeros = torch.zeros((d, width - used), dtype=x.dtype, device=x.device)
        rows = torch.cat([torch.zeros((d, nq), dtype=x.dtype, device=x.device), torch.diag(s_qd)], -1)
        rows = rows.expand(*lead, d, nq + d)
        if spec.lorentz_factor:
            slope, curve = lorentz_slopes(qdot)
            rows = torch.cat([rows, torch.diag_embed(slope * s_g)], -1)
        rows = torch.cat([rows, zeros.expand(*lead, d, width - used)], -1)
        mixed = torch.cat([q_features_jvp(spec, q, qdot) * s_q,
                           torch.zeros((*lead, width - nq), dtype=x.dtype, device=x.device)], -1)
        tangents = torch.cat([rows, mixed.unsqueeze(-2)], -2)
        g, gram = input_grad_and_tangent_hessian(self.params, x, tangents, spec, rows=d)
        hess = gram[..., :d, :d]
        if spec.lorentz_factor:
            hess = hess + torch.diag_embed(g[..., nq + d:nq + 2 * d] * s_g * curve)
        return hess, q_features_vjp(spec, q, g[..., :nq] * s_q) - gram[..., :d, d]

    def lagrangian(self, q, qdot, extra=None):
        """L (...,)."""
        self._check_state(q, qdot, extra)
        return self._lagrangian(q, qdot, extra)

    def velocity_hessian(self, q, qdot, extra=None):
        """(..., dof, dof)."""
        self._check_state(q, qdot, extra)
        d, extra = q.shape[-1], extra if self.spec.extra_inputs else None
        hess, _ = self._fast_terms(self._rows(q, d), self._rows(qdot, d), self._rows(extra))
        return hess.reshape(*q.shape, d)

    def acceleration_info(self, q, qdot, extra=None):
        """(qddot (..., dof), n_fallback) with spec.own.formulation."""
        self._check_state(q, qdot, extra)
        extra = extra if self.spec.extra_inputs else None
        if self.spec.own.formulation != "fast":
            return euler_lagrange_info(self._lagrangian, q, qdot, self.spec.own.formulation, extra)
        d = q.shape[-1]
        hess, rhs = self._fast_terms(self._rows(q, d), self._rows(qdot, d), self._rows(extra))
        if self.spec.dissipation:   # Rayleigh D = 1/2 sum b qdot^2 against L's orientation: -sign(tr H) b qdot
            b = torch.nn.functional.softplus(self.params["dissipation.raw"])
            side = torch.sign(torch.diagonal(hess, dim1=-2, dim2=-1).sum(-1, keepdim=True))
            rhs = rhs - side * (b if self.members is None else b[:, None, :]) * self._rows(qdot, d)
        return _solved(hess, rhs, q.shape[:-1])

    def acceleration(self, q, qdot, extra=None):
        """qddot (..., dof)."""
        return self.acceleration_info(q, qdot, extra)[0]
