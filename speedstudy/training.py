"""Training throughput on the double-pendulum protocol: JAX (jit) vs PyTorch (eager, torch.compile).

`training_rows(sizes, notes) -> rows {system, model, framework, mode, dtype, batch, steps_per_s,
samples_per_s, hidden}` for the claim's LNN (fast formulation) and baseline, with the claim's specs
(`replication.claims.double_pendulum.MODELS`) at `sizes.train_hidden` and its paper protocol (L1 loss,
Adam, l2 penalty) at batch `sizes.train_batch` (and each of `sizes.train_extra_batches`). One optimiser
step is timed (fastest of `sizes.train_steps` after one warm-up/compile step) with the training loops' own step functions:
`train_jax.make_step` (eqx.filter_jit) and `train_torch.make_loss` + torch.optim.Adam.
mode "compile" wraps the PyTorch loss in `torch.compile` (generated code in `lagbench.models.torch.inductor_cache`);
where that fails or is disabled, no row is written and the reason goes to `notes` (shown in ratios.csv).
"""
from __future__ import annotations

import time

import jax.numpy as jnp
import torch

import lagbench.models.jax
import lagbench.models.torch
from lagbench.models import ModelSpec, init_params
from lagbench.models.torch import inductor_cache
from lagbench.replication.claims.double_pendulum import MODELS, PROTOCOLS
from lagbench.replication.training import train_jax, train_torch
from lagbench.replication.training.data import BatchStream
from lagbench.speedstudy.timing import best_time

COMPILE_BUDGET_S = 240.0


def _spec(entry, hidden, dtype):
    return ModelSpec(dof=2, hidden=tuple(hidden), dtype=dtype, **entry.spec)


def _jax_step_time(spec, params, protocol, batch, reps):
    model = lagbench.models.jax.build(spec, params)
    opt, step = train_jax.make_step(spec, protocol)
    import equinox as eqx

    state = {"m": model, "s": opt.init(eqx.filter(model, eqx.is_inexact_array))}
    b = {k: jnp.asarray(v, jnp.dtype(protocol.dtype)) for k, v in batch.items()}
    lr = jnp.asarray(1e-5, jnp.dtype(protocol.dtype))

    def one():
        m, s, loss, _ = step(state["m"], state["s"], b, lr)
        float(loss)
        state["m"], state["s"] = m, s
    one()
    return best_time(one, min_time=0.0, min_reps=reps)


def _torch_step_time(spec, params, protocol, batch, reps, compile_=False):
    model = lagbench.models.torch.build(spec, params)
    loss_fn = train_torch.make_loss(spec, protocol)
    if compile_:
        if not inductor_cache.private():
            raise inductor_cache.InductorCacheError("no private folder for inductor's generated code (see the log)")
        loss_fn = torch.compile(loss_fn)
    opt = torch.optim.Adam(model.parameters(), lr=1e-5, **train_torch.ADAM_KERNEL)
    b = {k: torch.as_tensor(v, dtype=getattr(torch, protocol.dtype)) for k, v in batch.items()}

    def one():
        opt.zero_grad(set_to_none=True)
        loss = loss_fn(model, b)
        loss.backward()
        opt.step()
        float(loss.detach())
    t0 = time.perf_counter()
    one()
    if compile_ and time.perf_counter() - t0 > COMPILE_BUDGET_S:
        raise TimeoutError(f"torch.compile took {time.perf_counter() - t0:.0f} s to compile (budget "
                           f"{COMPILE_BUDGET_S:.0f} s)")
    return best_time(one, min_time=0.0, min_reps=reps)


def training_rows(sizes, notes: list, progress=None) -> list[dict]:
    rows = []
    for b in (sizes.train_batch, *sizes.train_extra_batches):
        rows += _rows_at(sizes, b, notes, progress)
    return rows


def _rows_at(sizes, batch_size, notes, progress) -> list[dict]:
    protocol = PROTOCOLS["paper"].replace(batch=batch_size, **{"data.n_train": batch_size * 4})
    batch = BatchStream(protocol, seed=0).batch(0)
    rows = []
    modes = [("jax", "jit"), ("torch", "eager")] + ([("torch", "compile")] if sizes.torch_compile else [])
    if not sizes.torch_compile and batch_size == sizes.train_batch:
        notes.append("training torch.compile: not measured at this size preset")
    for entry in MODELS:
        spec = _spec(entry, sizes.train_hidden, protocol.dtype)
        params = init_params(spec, seed=0)
        for fw, mode in modes:
            try:
                if fw == "jax":
                    dt = _jax_step_time(spec, params, protocol, batch, sizes.train_steps)
                else:
                    dt = _torch_step_time(spec, params, protocol, batch, sizes.train_steps, mode == "compile")
            except Exception as exc:  # torch.compile on CPU: a compiler or graph-break failure is a result
                notes.append(f"training {entry.label} torch {mode}: failed ({type(exc).__name__}: "
                             f"{str(exc).splitlines()[0][:160] if str(exc) else ''})")
                continue
            finally:
                if progress:
                    progress.update(1)
            rows.append({"system": "double_pendulum", "model": entry.label, "framework": fw, "mode": mode,
                         "dtype": protocol.dtype, "batch": protocol.batch, "steps_per_s": 1.0 / dt,
                         "samples_per_s": protocol.batch / dt, "hidden": "x".join(map(str, spec.hidden))})
    return rows


def n_training_cases(sizes) -> int:
    return len(MODELS) * (3 if sizes.torch_compile else 2) * (1 + len(sizes.train_extra_batches))
