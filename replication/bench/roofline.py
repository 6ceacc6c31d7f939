"""The fast/paper targets and the matmul roofline, at the paper's architecture.

`fast_paper_rows(sizes, dof)`: the LNN (`sizes.ratio_hidden` softplus, empirical init, float32, batch
`sizes.ratio_batch`) timed in both formulations and both frameworks -> rows {dof, framework,
formulation, batch, seconds, samples_per_s, flops_per_sample (JAX only: XLA's compiled cost analysis),
gflops (JAX only)}.
`matmul_rows(sizes, dof)`: the attainable rate: a plain MLP forward of the same layer shapes
(2d -> hidden -> 1, softplus) on batch * (d + 1) rows (the width of the fast formulation's batched
tangent products), FLOPs = 2 * sum(in * out) * rows (matrix products only) -> rows {dof, framework,
rows, seconds, gflops}.
The achieved fraction (fast LNN GFLOP/s over the plain MLP's GFLOP/s, same framework, same run) is
computed in `replication.bench.tables`.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import torch

from models import init_params
from models.jax.mlp import mlp as jmlp
from models.torch.mlp import mlp as tmlp
from replication.bench.evaluators import make_evaluator
from replication.bench.inference import model_spec
from replication.bench.timing import best_time

WARMUP_BATCH = 64


def _states(batch, d, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, (batch, d)), rng.uniform(-10, 10, (batch, d))


def fast_paper_rows(sizes, dof: int) -> list[dict]:
    rows = []
    q, qd = _states(sizes.ratio_batch, dof)
    for form in ("paper", "fast"):
        spec = model_spec("lnn", form, dof, sizes.ratio_hidden, "float32")
        params = init_params(spec, seed=0)
        for fw in ("jax", "torch"):
            ev = make_evaluator(fw, spec, params)
            args = ev.prepare(q, qd)
            if fw == "torch":
                ev.run(ev.prepare(q[:WARMUP_BATCH], qd[:WARMUP_BATCH]))
            else:
                ev.run(args)
            dt = best_time(lambda ev=ev, args=args: ev.run(args), min_time=sizes.min_time, min_reps=2)
            flops = ev.flops(args) / sizes.ratio_batch if fw == "jax" else float("nan")
            rows.append({"dof": dof, "framework": fw, "formulation": form, "batch": sizes.ratio_batch,
                         "seconds": dt, "samples_per_s": sizes.ratio_batch / dt, "flops_per_sample": flops,
                         "gflops": flops * sizes.ratio_batch / dt / 1e9})
    return rows


def matmul_rows(sizes, dof: int) -> list[dict]:
    spec = model_spec("lnn", "fast", dof, sizes.ratio_hidden, "float32")
    params = init_params(spec, seed=0)
    n_rows = sizes.ratio_batch * (dof + 1)
    widths = spec.mlp_sizes()
    flops = 2.0 * sum(a * b for a, b in zip(widths[:-1], widths[1:], strict=True)) * n_rows
    x = np.random.default_rng(0).normal(size=(n_rows, widths[0]))
    jp = {k: jnp.asarray(v, jnp.float32) for k, v in params.items()}
    jx = jnp.asarray(x, jnp.float32)
    f = jax.jit(lambda p, a: jmlp(p, a, spec)).lower(jp, jx).compile()
    tj = best_time(lambda: jax.block_until_ready(f(jp, jx)), min_time=sizes.min_time, min_reps=3)
    tp = {k: torch.as_tensor(v, dtype=torch.float32) for k, v in params.items()}
    tx = torch.as_tensor(x, dtype=torch.float32)

    def run_torch():
        with torch.no_grad():
            tmlp(tp, tx, spec)
    run_torch()
    tt = best_time(run_torch, min_time=sizes.min_time, min_reps=3)
    return [{"dof": dof, "framework": fw, "rows": n_rows, "seconds": t, "gflops": flops / t / 1e9}
            for fw, t in (("jax", tj), ("torch", tt))]
