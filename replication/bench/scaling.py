"""Scaling study: cost per evaluation against size, and the fitted power-law exponents.

Studies (rows {study, formulation, framework, n, batch, seconds_per_eval, samples_per_s}):
  "lgn_grid":  the Lagrangian graph network (density MLP `sizes.lgn_hidden`, radius 1) on a periodic grid
               of n nodes, "dense" (full n x n velocity Hessian + solve) vs "banded" (coloured band, O(n)
               solve). Batch max(1, 1024 // n) samples per call, so every call holds about the same number
               of nodes; seconds_per_eval is per sample (one grid state). Dense stops at `MAX_DENSE_N`.
  "lnn_chain": the LNN (`sizes.ratio_hidden`, softplus) on d = n degrees of freedom (the pendulum chain's
               state shape; random normal states, the cost does not depend on the values), "fast" vs
               "paper", batch `sizes.chain_batch`.
`fit_exponents(rows)` -> rows {study, formulation, framework, exponent, fit_range, n_min, n_max}: the
least-squares slope of log(seconds_per_eval) on log(n) over all measured sizes (fit_range "all") and
without the smallest size ("n>=N": the asymptotic trend; the banded target is an exponent <= 1.1).
"""
from __future__ import annotations

import time

import numpy as np

from models import init_params
from replication.bench.evaluators import make_evaluator
from replication.bench.inference import model_spec
from replication.bench.timing import LONG_CALL_S, best_time

MAX_DENSE_N = 2048
FRAMEWORKS = ("jax", "torch")


def _time_eval(spec, framework, n, batch, min_time, seed=0):
    ev = make_evaluator(framework, spec, init_params(spec, seed=0))
    rng = np.random.default_rng(seed)
    args = ev.prepare(rng.normal(size=(batch, n)), rng.normal(size=(batch, n)))
    t0 = time.perf_counter()
    ev.run(args)  # JAX: compiles; eager PyTorch: already a representative call
    first = time.perf_counter() - t0
    if framework == "torch" and first >= LONG_CALL_S:
        return first
    return best_time(lambda: ev.run(args), min_time=min_time, min_reps=2)


def lgn_cases(sizes):
    for form in ("dense", "banded"):
        for n in sizes.lgn_n:
            if form == "dense" and n > MAX_DENSE_N:
                continue
            for fw in FRAMEWORKS:
                yield ("lgn_grid", form, fw, n, max(1, 1024 // n))


def chain_cases(sizes):
    for form in ("fast", "paper"):
        for d in sizes.chain_d:
            for fw in FRAMEWORKS:
                yield ("lnn_chain", form, fw, d, sizes.chain_batch)


def run_scaling_case(case, sizes) -> dict:
    study, form, fw, n, batch = case
    if study == "lgn_grid":
        spec = model_spec("lgn", form, n, sizes.lgn_hidden, "float32", lgn_radius=1)
    else:
        spec = model_spec("lnn", form, n, sizes.ratio_hidden, "float32")
    dt = _time_eval(spec, fw, n, batch, sizes.min_time)
    return {"study": study, "formulation": form, "framework": fw, "n": int(n), "batch": int(batch),
            "seconds_per_eval": dt / batch, "samples_per_s": batch / dt}


def _slope(n, t):
    return float(np.polyfit(np.log(n), np.log(t), 1)[0])


def fit_exponents(rows) -> list[dict]:
    groups: dict = {}
    for r in rows:
        groups.setdefault((r["study"], r["formulation"], r["framework"]), []).append(r)
    out = []
    for (study, form, fw), g in sorted(groups.items()):
        n = np.array([r["n"] for r in g], float)
        t = np.array([r["seconds_per_eval"] for r in g], float)
        ok = np.isfinite(t) & (t > 0)
        n, t = n[ok], t[ok]
        sizes = sorted(set(n))
        fits = [("all", n >= sizes[0])] if len(sizes) >= 2 else []
        if len(sizes) >= 3:  # without the smallest size, where fixed per-call costs dominate
            fits.append((f"n>={int(sizes[1])}", n >= sizes[1]))
        for label, sel in fits:
            out.append({"study": study, "formulation": form, "framework": fw, "exponent": _slope(n[sel], t[sel]),
                        "fit_range": label, "n_min": int(n[sel].min()), "n_max": int(n[sel].max())})
    return out
