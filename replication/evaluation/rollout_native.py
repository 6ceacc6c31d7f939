"""Long rollouts in the model's own framework: the shared RK4 (`rollout.rk4_step`) over many sample
intervals per call, so a trajectory of 10^4-10^6 samples is not 10^5-10^7 NumPy <-> framework round trips.

`native_rollout(framework, model, dtype, field, z0, t_eval, dt, *, forcing=None, progress=None) -> z`
is `rollout.rollout(f, z0, t_eval, dt)` (step rule "split") with f the model's field, to float rounding:
the same intervals and step sizes (`plan`), the state and the RK4 arithmetic in float64, the model called
on the state cast to `dtype`, a row that turns non-finite frozen at NaN from then on.
  framework  "jax" (one jit-compiled `lax.scan` over BLOCK intervals a call, compiled once per batch shape)
             or "torch" (the loop in torch tensors on the default device, no NumPy conversions; from
             COMPILE_CALLS model calls on, its RK4 step as one AOTInductor library: `_compiled`)
  model      the framework model (`models.jax.build` / `models.torch.build`)
  field      "acceleration" (z = (q, qdot), dz/dt = (qdot, model.acceleration(q, qdot, tau))) or
             "time_derivative" (an HNN on (x, y) = (q, qdot): dz/dt = model.time_derivative(x, y))
  forcing    None, or tau (B, T, dof) at the times t_eval: the state then carries the time since the start,
             and tau at a stage's time is interpolated linearly between the interval's two samples, as
             `np.interp` does (the model is DeLaN's forward model, tau its extra input)
  progress   called with the number of intervals done, after each block of BLOCK
z0 (B, 2 dof) float64, t_eval (T,); returns z (B, T, 2 dof) float64.
"""
from __future__ import annotations

import numpy as np

from lagbench.replication.evaluation.adapters import padded_size
from lagbench.replication.evaluation.rollout import rk4_step, steps

BLOCK = 256   # intervals a compiled JAX call advances; the progress bar moves once a block
COMPILE_CALLS = 40_000   # model calls from which a PyTorch rollout compiles its RK4 step (eager ~1 ms a call)


def plan(t_eval, dt):
    """(n (T-1,) int, h (T-1,) float64): RK4 steps and step size of each interval, as `rollout` splits them."""
    t = np.asarray(t_eval, np.float64)
    pairs = [steps(d, dt, "split", np.float64) for d in np.diff(t)]
    return np.array([n for n, _ in pairs], np.int64), np.array([float(h) for _, h in pairs], np.float64)


def native_rollout(framework, model, dtype, field, z0, t_eval, dt, *, forcing=None, progress=None):
    z0 = np.asarray(z0, np.float64)
    t = np.asarray(t_eval, np.float64)
    n, h = plan(t, dt)
    tau = None if forcing is None else np.asarray(forcing, np.float64)
    if forcing is not None:   # z = (q, qdot, time since the start), as the NumPy rollout under torques
        z0 = np.concatenate([z0, np.zeros((len(z0), 1))], 1)
    if framework == "jax":
        z = _jax(model, dtype, field, z0, t - t[0], n, h, tau, progress)
    elif framework == "torch":
        z = _torch(model, dtype, field, z0, t - t[0], n, h, tau, progress)
    else:
        raise ValueError(f"unknown framework {framework!r}; valid: jax, torch")
    return z if forcing is None else z[..., :-1]


def _vector_field(fn, cast, field, dof, forced, cat, ones, like):
    """f(y, ta, tb, tau_a, tau_b) -> dy/dt: y = (q, qdot) (or (q, qdot, t) when forced; tau then linear in t
    between the interval's samples at ta and tb), float64; fn(q, qdot, tau) the model's output (its
    acceleration, or the HNN's (xdot, ydot)) on inputs cast to the model's dtype by `cast`."""
    def f(y, ta, tb, tau_a, tau_b):
        q, v = cast(y[:, :dof]), cast(y[:, dof:2 * dof])
        if field == "time_derivative":
            return cat([like(part, y) for part in fn(q, v, None)], 1)
        tau = None
        if forced:
            w = ((y[:, -1] - ta) / (tb - ta))[:, None]
            tau = cast(tau_a + w * (tau_b - tau_a))
        d = cat([y[:, dof:2 * dof], like(fn(q, v, tau), y)], 1)
        return cat([d, ones(y)], 1) if forced else d
    return f


def _method(model, field):
    """fn(q, qdot, tau) of `_vector_field` from the framework model."""
    if field == "time_derivative":
        return lambda q, v, tau: model.time_derivative(q, v, None)
    return lambda q, v, tau: model.acceleration(q, v, tau)


def _jax(model, dtype, field, z0, t, n, h, tau, progress):
    import jax.numpy as jnp

    b, k = z0.shape
    size = padded_size(b)
    m = n.size
    total = -(-m // BLOCK) * BLOCK

    def pad(a):   # the last block filled with intervals of zero steps
        return np.concatenate([a, np.repeat(a[-1:], total - m, axis=0)])
    n, h, ta, tb = np.concatenate([n, np.zeros(total - m, np.int64)]), pad(h), pad(t[:-1]), pad(t[1:])
    rows = np.concatenate([z0, np.repeat(z0[:1], size - b, 0)])
    if tau is not None:
        tau = np.moveaxis(np.concatenate([tau, np.repeat(tau[:1], size - b, 0)]), 1, 0)   # (T, size, dof)
        ua, ub = pad(tau[:-1]), pad(tau[1:])
    else:
        ua = ub = np.zeros((total, 1, 1))
    block = _jax_block(field, tau is not None, str(jnp.dtype(dtype)), (k - (tau is not None)) // 2)
    z, alive = jnp.asarray(rows), jnp.ones(size, bool)
    out = np.full((b, t.size, k), np.nan)
    out[:, 0] = z0
    for s in range(0, total, BLOCK):
        z, alive, zs = block(model, z, alive, *(jnp.asarray(a[s:s + BLOCK]) for a in (h, n, ta, tb, ua, ub)))
        got = np.asarray(zs)[:min(BLOCK, m - s), :b]
        out[:, 1 + s:1 + s + got.shape[0]] = np.moveaxis(got, 0, 1)
        if progress is not None:
            progress(min(s + BLOCK, m))
    return out


_BLOCKS: dict = {}


def _jax_block(field, forced, dtype, dof):
    """The compiled call advancing BLOCK intervals, one per (field, forced, dtype, dof) per process."""
    key = (field, forced, dtype, dof)
    if key in _BLOCKS:
        return _BLOCKS[key]
    import equinox as eqx
    import jax
    import jax.numpy as jnp

    def block(model, z, alive, h, n, ta, tb, ua, ub):
        f = _vector_field(_method(model, field), lambda x: x.astype(dtype), field, dof, forced, jnp.concatenate,
                          lambda y: jnp.ones((y.shape[0], 1), y.dtype), lambda a, y: a.astype(y.dtype))

        def interval(carry, xs):
            hj, nj, a, bb, tau_a, tau_b = xs

            def one(_, state):
                y, ok = state
                y = rk4_step(lambda x: f(x, a, bb, tau_a, tau_b), y, hj)
                bad = ~jnp.all(jnp.isfinite(y), axis=1)
                return jnp.where(bad[:, None], 0.0, y), ok & ~bad

            z, alive = jax.lax.fori_loop(0, nj, one, carry)
            return (z, alive), jnp.where(alive[:, None], z, jnp.nan)

        (z, alive), zs = jax.lax.scan(interval, (z, alive), (h, n, ta, tb, ua, ub))
        return z, alive, zs

    _BLOCKS[key] = eqx.filter_jit(block)
    return _BLOCKS[key]


def _torch(model, dtype, field, z0, t, n, h, tau, progress):
    import torch

    b, k = z0.shape
    forced = tau is not None
    eager = _torch_step(model, dtype, field, (k - forced) // 2, forced)
    step = (_compiled(eager, k, forced, b) if 4 * int(n.sum()) >= COMPILE_CALLS else None) or eager
    tau = torch.as_tensor(tau) if forced else torch.zeros((b, t.size, 0), dtype=torch.float64)
    z = torch.as_tensor(z0)
    alive = torch.ones(b, dtype=torch.bool)
    out = torch.full((b, t.size, k), float("nan"), dtype=torch.float64)
    out[:, 0] = z
    with torch.no_grad():
        for j in range(n.size):
            ctx = torch.cat([torch.tensor([[h[j], t[j], t[j + 1]]], dtype=torch.float64).expand(b, 3),
                             tau[:, j], tau[:, j + 1]], 1)
            for _ in range(int(n[j])):
                z, bad = _rows_apart(step, eager, torch.cat([z, ctx], 1), k)
                if bad.any():
                    alive &= ~bad
            out[alive, j + 1] = z[alive]
            if progress is not None and ((j + 1) % BLOCK == 0 or j + 1 == n.size):
                progress(j + 1)
    return out.cpu().numpy()


def _rows_apart(step, eager, x, k):
    """step(x); where a row makes PyTorch raise (a linear solve on a diverging state's singular matrix), the
    rows stepped one by one by `eager` and each raising row flagged bad (its k state entries 0), as a NaN
    row would be: rows never mix, so the others are what the batch would give."""
    import torch

    try:
        return step(x)
    except RuntimeError:
        zs, bads = [], []
        for i in range(x.shape[0]):
            try:
                z, bad = eager(x[i:i + 1])
            except RuntimeError:
                z, bad = torch.zeros_like(x[i:i + 1, :k]), torch.ones(1, dtype=torch.bool)
            zs.append(z)
            bads.append(bad)
        return torch.cat(zs), torch.cat(bads)


def _torch_step(model, dtype, field, dof, forced):
    """step(x) -> (z', bad): one RK4 step of x = [z, h, ta, tb, tau_a, tau_b] (one row a trajectory, float64:
    the state, the step, the interval's ends and its torques), rows that turned non-finite set to 0 and
    flagged in `bad`."""
    import torch

    f = _vector_field(_method(model, field), lambda x: x.to(getattr(torch, str(dtype))), field, dof, forced,
                      torch.cat, lambda y: torch.ones((y.shape[0], 1), dtype=y.dtype), lambda a, y: a.to(y.dtype))
    k = 2 * dof + forced

    def step(x):
        z, h, ta, tb = x[:, :k], x[:, k:k + 1], x[:, k + 1], x[:, k + 2]
        tau_a, tau_b = x[:, k + 3:k + 3 + dof], x[:, k + 3 + dof:]
        z = rk4_step(lambda y: f(y, ta, tb, tau_a, tau_b), z, h)
        bad = ~torch.isfinite(z).all(1)
        return torch.where(bad[:, None], torch.zeros_like(z), z), bad
    return step


def _compiled(step, k, forced, batch):
    """`step` as one AOTInductor library for this batch size (`models.torch.compiled.compile_batched`: 15-40 s
    to build, then one call a step in place of ~100 eager operators), or None (with a warning naming why)
    where it cannot be built: the rollout then runs eagerly."""
    import torch

    from lagbench.replication.training.compile_torch import compiler

    if torch.get_default_device().type == "cpu" and compiler() is None:
        import warnings

        warnings.warn("the rollout runs eagerly: compiling its step needs a C++ compiler (set CXX or install g++)",
                      stacklevel=2)
        return None
    try:
        from lagbench.models.torch.compiled import compile_batched

        dof = (k - forced) // 2
        return compile_batched(step, 1, k + 3 + 2 * dof * forced, "float64", batch=batch, name="rk4 step",
                               flatten=True)
    except Exception as e:  # noqa: BLE001  (a compiler missing, an operator the export cannot take)
        import warnings

        warnings.warn(f"the rollout runs eagerly: compiling its step failed ({type(e).__name__}: "
                      f"{str(e).splitlines()[0] if str(e) else ''})", stacklevel=2)
        return None
