"""Single-sample latency (online control: one state in, torque or acceleration out), DeLaN on the double
pendulum.

`latency_rows(sizes) -> rows {system, model, method, framework, dtype, mode, dispatch, threads, hidden,
evals_per_s, max_abs_diff, ops}`: evaluations per second of ONE sample (inputs of shape (dof,), results
blocked on), for method "inverse_dynamics" (q, qdot, qddot) -> tau and "acceleration" (q, qdot) -> qddot.
Modes: JAX "method" (the model's eqx.filter_jit method, as a user calls it), "compile_single" and
"compile_single_frozen" (`lagbench.models.jax.compiled.compile_single`, parameters as arguments / as constants);
PyTorch "eager" (the method under torch.no_grad) and, where `sizes.torch_compile` (not the tiny preset: 15-40 s
of compiling per method), "compile_single" (`lagbench.models.torch.compiled.compile_single`: torch.export +
AOTInductor, parameters as constants; ops None). max_abs_diff: largest |difference| against the model
method on the same sample (0 for the method itself); ops: XLA kernels of the compiled program, or the
ATen operators of one PyTorch call (None for the eqx method).
Each dispatch setting runs in a fresh Python process (`python -m lagbench.speedstudy.latency`), because
JAX's CPU client fixes it when it starts: "async" (JAX's default: programs run on a worker thread) and
"sync" (`use_sync_dispatch()`: inline in the caller). Both processes run on one core's worth of threads
(XLA: no multi-threaded Eigen, intra-op parallelism 1; PyTorch: 1 thread); PyTorch is measured once, in
the sync process (dispatch "-"). Timing: the modes are interleaved in windows of `CALLS` calls and each
mode's fastest window gives its rate, so a burst of load from other processes hits all modes alike.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from lagbench.replication.run.environment import one_thread_env
from lagbench.speedstudy.evaluators import torch_ops, xla_kernels

METHODS = ("inverse_dynamics", "acceleration")
CALLS = 50
SLICE_S = 0.05  # each fn's turn in `interleaved_rates`


def interleaved_rates(fns: dict, seconds: float, calls: int = CALLS, slice_s: float = SLICE_S) -> dict:
    """{name: calls per second}: the fastest window of `calls` calls per fn. The fns take turns, each
    running windows for `slice_s` seconds (at least one) per turn, so every fn gets the same share of
    time and a fast fn many windows. With one window per turn, the fast compiled fns got as few windows
    as eager had (3-6), and on this shared machine the best of so few was far from the best of many:
    PyTorch compile_single 11-12k calls/s beside eager against 16-18k alone, 0.3 s each (measured, DeLaN
    3 x 128). Load bursts here last about as long as 0.3 s, so `seconds` should be 2 or more: 3 s gave
    18.6-18.8k in every repeat."""
    best = dict.fromkeys(fns, float("inf"))
    for f in fns.values():
        f()
    t_end, rounds = time.perf_counter() + seconds, 0
    while rounds < 3 or time.perf_counter() < t_end:
        for k, f in fns.items():
            t_turn = time.perf_counter() + slice_s
            while True:
                t0 = time.perf_counter()
                for _ in range(calls):
                    f()
                t1 = time.perf_counter()
                best[k] = min(best[k], (t1 - t0) / calls)
                if t1 >= t_turn:
                    break
        rounds += 1
    return {k: 1.0 / v for k, v in best.items()}


def _jax_fns(spec, params, method, x):
    import jax
    import jax.numpy as jnp

    import lagbench.models.jax
    from lagbench.models.jax.compiled import compile_single

    m = lagbench.models.jax.build(spec, params)
    xs = [jnp.asarray(v, spec.dtype) for v in x]
    call = getattr(m, method)
    ref = np.asarray(call(*xs), np.float64)
    fns, diffs, ops = {"method": lambda: jax.block_until_ready(call(*xs))}, {"method": 0.0}, {"method": None}
    for mode, frozen in (("compile_single", False), ("compile_single_frozen", True)):
        f = compile_single(m, method, freeze=frozen)
        diffs[mode] = float(np.max(np.abs(np.asarray(f(*xs), np.float64) - ref)))
        fns[mode] = (lambda f=f: f(*xs).block_until_ready())
        ops[mode] = xla_kernels(f.compiled)
    return fns, diffs, ops


def _torch_fns(spec, params, method, x, aot: bool):
    import torch

    import lagbench.models.torch
    from lagbench.models.torch.compiled import compile_single

    m = lagbench.models.torch.build(spec, params)
    xs = [torch.as_tensor(v, dtype=getattr(torch, spec.dtype)) for v in x]
    call = getattr(m, method)

    def run():
        with torch.no_grad():
            return call(*xs)
    fns, diffs, ops = {"eager": run}, {"eager": 0.0}, {"eager": torch_ops(run)}
    if aot:
        f = compile_single(m, method)
        diffs["compile_single"] = float((f(*xs) - run()).abs().max())
        fns["compile_single"], ops["compile_single"] = (lambda: f(*xs)), None
    return fns, diffs, ops


def measure(hidden: tuple, dtypes: tuple, seconds: float, sync: bool, methods: tuple = METHODS,
            torch_aot: bool = False) -> list[dict]:
    """The rows of one process (call with a fresh interpreter: `sync` must be set before JAX starts)."""
    from lagbench.models.jax.compiled import async_dispatch, use_sync_dispatch

    if sync and not use_sync_dispatch():
        raise RuntimeError("JAX's backend had started before the latency study could set sync dispatch")
    import torch

    from lagbench.models import init_params
    from lagbench.speedstudy.inference import model_spec

    torch.set_num_threads(1)
    rng = np.random.default_rng(0)
    rows = []
    for dtype in dtypes:
        spec = model_spec("delan", "-", 2, hidden, dtype)
        params = init_params(spec, seed=0)
        for method in methods:
            x = [rng.uniform(-1, 1, 2) for _ in range(3 if method == "inverse_dynamics" else 2)]
            fws = [("jax", *_jax_fns(spec, params, method, x))]
            if sync:
                fws.append(("torch", *_torch_fns(spec, params, method, x, torch_aot)))
            for fw, fns, diffs, ops in fws:
                for mode, rate in interleaved_rates(fns, seconds).items():
                    rows.append({"system": "double_pendulum", "model": "delan", "method": method,
                                 "framework": fw, "dtype": dtype, "mode": mode,
                                 "dispatch": ("async" if async_dispatch() else "sync") if fw == "jax" else "-",
                                 "threads": 1, "hidden": "x".join(map(str, hidden)), "evals_per_s": rate,
                                 "max_abs_diff": diffs[mode], "ops": ops[mode]})
    return rows


def latency_rows(sizes, notes: list | None = None) -> list[dict]:
    """Both dispatch settings, each in its own process (`sizes.hidden`, `sizes.latency_dtypes`,
    `sizes.latency_s` seconds per case)."""
    rows = []
    for sync in (False, True):
        arg = json.dumps({"hidden": list(sizes.hidden), "dtypes": list(sizes.latency_dtypes),
                          "seconds": sizes.latency_s, "sync": sync,
                          "methods": list(sizes.latency_methods), "torch_aot": sizes.torch_compile})
        root = str(Path(__file__).resolve().parents[1])  # the project root, for an uninstalled checkout
        env = {**os.environ, **one_thread_env(os.environ),
               "PYTHONPATH": os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH", "")) if p)}
        proc = subprocess.run([sys.executable, "-m", "lagbench.speedstudy.latency", arg], env=env,
                              capture_output=True, text=True, timeout=600)
        if proc.returncode != 0:
            msg = (proc.stderr.strip().splitlines() or ["no output"])[-1][:200]
            if notes is None:
                raise RuntimeError(f"latency study (sync={sync}) failed: {msg}")
            notes.append(f"latency study (sync={sync}) failed: {msg}")
            continue
        rows += json.loads(proc.stdout.strip().splitlines()[-1])
    return rows


if __name__ == "__main__":
    a = json.loads(sys.argv[1])
    print(json.dumps(measure(tuple(a["hidden"]), tuple(a["dtypes"]), a["seconds"], a["sync"], tuple(a["methods"]),
                             a.get("torch_aot", False))))
