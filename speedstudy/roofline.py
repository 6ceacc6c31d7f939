"""The fast/paper targets and the matmul roofline, at the paper's architecture.

`roofline_rows(sizes, dof) -> (fast_paper rows, matmul rows)`.
fast/paper: the LNN (`sizes.ratio_hidden` softplus, empirical init, float32, batch `sizes.ratio_batch`)
timed in both formulations and both frameworks -> rows {dof, framework, formulation, mode, batch, seconds,
samples_per_s, flops_per_sample (JAX only: XLA's compiled cost analysis), gflops (JAX only), threads}.
PyTorch has its eager rows and, where `sizes.torch_compile`, compiled ones (COMPILED_MODES: the fast LNN
through AOTInductor, mode "aoti"; the paper LNN, whose torch.func does not export, traced first, mode
"traced"; `evaluators`); the tables take each formulation's fastest mode.
matmul: the attainable rate: the chain of matrix products of the same layer shapes (2d -> hidden -> 1,
a ReLU between) on batch * (d + 1) rows (the width of the fast formulation's batched
tangent products), FLOPs = 2 * sum(in * out) * rows (matrix products only) -> rows {dof, framework,
rows, seconds, gflops, threads}. The three are timed interleaved, so that changing load hits them alike.
PyTorch runs the interleaved rounds once at each of `inference.TORCH_THREAD_CHOICES` intra-op threads (1 and
all cores, as the inference rows) and each of the three keeps its faster count (`threads`; JAX: "default",
XLA's pool over all cores), so neither framework is held to fewer cores than the other.
The achieved fraction (fast LNN GFLOP/s over the matrix-product chain's GFLOP/s, same framework, same run) is
computed in `speedstudy.tables`.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import torch

from lagbench.models import init_params
from lagbench.speedstudy.device import sync
from lagbench.speedstudy.evaluators import make_evaluator
from lagbench.speedstudy.inference import model_spec, torch_thread_choices
from lagbench.speedstudy.timing import interleaved_best, torch_threads

COMPILED_MODES = (("fast", "aoti"), ("paper", "traced"))  # PyTorch compiled rows where sizes.torch_compile


def _states(batch, d, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, (batch, d)), rng.uniform(-10, 10, (batch, d))


def _matmul_chain(framework, params, n_layers, n_rows, n_in):
    """x (n_rows, n_in) through the MLP's weight matrices: x <- relu(x @ W_i^T), the last without relu.
    The ReLU (one cheap pass) only keeps the compiler from reassociating the chain of products."""
    x = np.random.default_rng(0).normal(size=(n_rows, n_in))
    keys = [f"mlp.{i}.weight" for i in range(n_layers)]
    if framework == "jax":
        ws = [jnp.asarray(params[k], jnp.float32) for k in keys]

        def chain(ws, a):
            for i, w in enumerate(ws):
                a = a @ w.T
                a = jnp.maximum(a, 0.0) if i < len(ws) - 1 else a
            return a
        f, jx = jax.jit(chain), jnp.asarray(x, jnp.float32)
        return lambda: jax.block_until_ready(f(ws, jx))
    ws = [torch.as_tensor(params[k], dtype=torch.float32) for k in keys]
    tx = torch.as_tensor(x, dtype=torch.float32)

    def run():
        with torch.no_grad():
            a = tx
            for i, w in enumerate(ws):
                a = a @ w.T
                a = torch.relu(a) if i < len(ws) - 1 else a
        sync()
    return run


def _best_over_threads(fns: dict, reps: int, framework: str) -> dict:
    """{name: (fastest seconds, threads)}: JAX once (its first call compiles: warmed up); PyTorch once per
    thread count in TORCH_THREAD_CHOICES (eager: no warm-up, a d = 16 paper call takes 15 s), faster kept."""
    if framework == "jax":
        for fn in fns.values():
            fn()
        return {k: (t, "default") for k, t in interleaved_best(fns, min_rounds=reps).items()}
    best = {k: (float("inf"), None) for k in fns}
    for n in torch_thread_choices():
        with torch_threads(n):
            for k, t in interleaved_best(fns, min_rounds=reps).items():
                best[k] = min(best[k], (t, n))
    return best


def roofline_rows(sizes, dof: int) -> tuple[list[dict], list[dict]]:
    """(fast/paper rows, matmul rows) for one dof; per framework the paper LNN, the fast LNN and the matrix
    products are timed interleaved (`timing.interleaved_best`, `sizes.ratio_reps` rounds)."""
    q, qd = _states(sizes.ratio_batch, dof)
    specs = {f: model_spec("lnn", f, dof, sizes.ratio_hidden, "float32") for f in ("paper", "fast")}
    params = init_params(specs["fast"], seed=0)  # the same MLP layout and weights for both formulations
    n_rows = sizes.ratio_batch * (dof + 1)
    widths = specs["fast"].mlp_sizes()
    mm_flops = 2.0 * sum(a * b for a, b in zip(widths[:-1], widths[1:], strict=True)) * n_rows
    fp, mm = [], []
    for fw in ("jax", "torch"):
        evs = {(f, None): make_evaluator(fw, spec, params) for f, spec in specs.items()}
        if fw == "torch" and sizes.torch_compile:
            evs.update({(f, m): make_evaluator(fw, specs[f], params, mode=m) for f, m in COMPILED_MODES})
        argss = {k: ev.prepare(q, qd) for k, ev in evs.items()}
        fns = {k: (lambda ev=ev, a=argss[k]: ev.run(a)) for k, ev in evs.items()}
        fns["matmul"] = _matmul_chain(fw, params, len(widths) - 1, n_rows, widths[0])
        best = _best_over_threads(fns, sizes.ratio_reps, fw)
        for (f, mode), ev in evs.items():
            flops = ev.flops(argss[f, mode]) / sizes.ratio_batch if fw == "jax" else float("nan")
            sec, threads = best[f, mode]
            fp.append({"dof": dof, "framework": fw, "formulation": f, "mode": ev.mode, "batch": sizes.ratio_batch,
                       "seconds": sec, "samples_per_s": sizes.ratio_batch / sec, "flops_per_sample": flops,
                       "gflops": flops * sizes.ratio_batch / sec / 1e9, "threads": threads})
        sec, threads = best["matmul"]
        mm.append({"dof": dof, "framework": fw, "rows": n_rows, "seconds": sec, "gflops": mm_flops / sec / 1e9,
                   "threads": threads})
    return fp, mm
