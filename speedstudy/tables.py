"""ratios.csv (JAX against PyTorch, per measured operation) and targets.json (issue targets, met or not).

`ratio_rows(inference, training, scaling, fastpaper, matmul, notes) -> rows {operation, kind, dof, jax, torch,
ratio, note}`: `operation` is for readers; `kind` (`KINDS`) and `dof` (where the row has one) say what the row
measures, and are what `speedstudy.targets` selects by; jax and torch are throughputs (samples/s, steps/s for training, GFLOP/s for the roofline rows);
ratio = jax / torch (above 1: JAX faster). A ratio beyond 2x either way carries a reason in `note`, made
from the data: for q'' rows, the call time fitted over the case's batch sizes (fixed per-call cost +
batch x per-sample cost, per framework; which term makes the difference) and the kernels per call
(XLA's fused kernels, PyTorch's ATen operators); for other rows the batch, the kind of operation and
the thread counts.
Also rows for the fast/paper speedups (jax, torch = each framework's fast/paper ratio; ratio empty),
the fast LNN's achieved GFLOP/s (XLA's FLOP count for both frameworks), the attainable (matrix products)
GFLOP/s and the achieved fraction.
KINDS: latency (one-sample DeLaN), inference (batched q''), training (steps/s), scaling, fast_paper (the
3 x 600 q'' rows per formulation), fast_over_paper (the speedup), matmul (the roofline), achieved (the fast
LNN's GFLOP/s), roofline_fraction, note.
The issue's numeric targets are checked in `speedstudy.targets`.
"""
from __future__ import annotations

import os

import numpy as np

from lagbench.speedstudy.bounds import TARGETS
from lagbench.speedstudy.timing import TORCH_THREADS

KINDS = ("latency", "inference", "training", "scaling", "fast_paper", "fast_over_paper", "matmul", "achieved",
         "roofline_fraction", "note")


def _fit_call_cost(rows) -> dict:
    """{(system, model, formulation, dtype, framework): (t0 s/call, t1 s/sample)}: the call time
    b / samples_per_s = t0 + b t1 through the smallest and the largest batch of a case (needs two batch
    sizes; t1 >= 0, t0 >= 0), so that both ends of the batch range are reproduced exactly."""
    by: dict = {}
    for r in rows:
        by.setdefault((r["system"], r["model"], r["formulation"], r["dtype"], r["framework"]), []).append(r)
    fit = {}
    for k, rs in by.items():
        lo, hi = min(rs, key=lambda r: r["batch"]), max(rs, key=lambda r: r["batch"])
        if lo["batch"] == hi["batch"]:
            continue
        t_lo, t_hi = lo["batch"] / lo["samples_per_s"], hi["batch"] / hi["samples_per_s"]
        t1 = max((t_hi - t_lo) / (hi["batch"] - lo["batch"]), 0.0)
        fit[k] = (max(t_lo - lo["batch"] * t1, 0.0), t1)
    return fit


def _count(x) -> str:
    return "?" if x is None or not np.isfinite(x) else str(int(x))


def _us(x) -> str:
    return f"{x * 1e6:.3g} us"


def fastest_per_batch(rows) -> list[dict]:
    """The inference rows with one row per (system, model, formulation, framework, dtype, source, batch):
    the fastest of its modes (PyTorch eager / aoti / traced) and thread counts."""
    best: dict = {}
    for r in rows:
        k = tuple(r.get(c) for c in ("system", "model", "formulation", "framework", "dtype", "source", "batch"))
        if k not in best or r["samples_per_s"] > best[k]["samples_per_s"]:
            best[k] = r
    return list(best.values())


def paired_best(rows) -> dict:
    """{(system, model, formulation, dtype, batch): PyTorch row} for the rows that carry the JAX rate timed
    in their own interleaved rounds (`jax_paired_samples_per_s`, `inference.run_case`): per operation the
    PyTorch row (any mode and thread count) with the lowest JAX-over-PyTorch ratio within its rounds."""
    best: dict = {}
    for r in rows:
        jp = r.get("jax_paired_samples_per_s")
        if r.get("framework") != "torch" or jp is None or not np.isfinite(jp) or not r["samples_per_s"] > 0:
            continue
        k = tuple(r.get(c) for c in ("system", "model", "formulation", "dtype", "batch"))
        if k not in best or jp / r["samples_per_s"] < best[k]["jax_paired_samples_per_s"] / best[k]["samples_per_s"]:
            best[k] = r
    return best


def _inference_note(key, b, j_rate, t_rate, fit, ops, how="") -> str:
    """Why JAX and PyTorch differ at this batch, from the batch fit and the kernel counts (measured)."""
    ratio = j_rate / t_rate
    j, t = fit.get((*key, "jax")), fit.get((*key, "torch"))
    oj, ot = ops.get((*key, "jax")), ops.get((*key, "torch"))
    parts = []
    if j and t:
        fixed, per = t[0] - j[0], b * (t[1] - j[1])
        slow = "PyTorch" if ratio > 1 else "JAX"
        dominant = "fixed per-call cost (dispatch)" if abs(fixed) >= abs(per) else "per-sample compute"
        parts.append(f"{slow} slower mainly by {dominant}: call = fixed + batch x per-sample through the "
                     f"smallest and largest batch: fixed JAX {_us(j[0])}, PyTorch {_us(t[0])}; per-sample JAX "
                     f"{_us(j[1])}, PyTorch {_us(t[1])}")
    else:  # one batch size: no fit; what the row is says which cost dominates
        parts.append(_generic_note("q''", ratio, b, b / min(j_rate, t_rate)))
    if "?" not in (_count(oj), _count(ot)):
        parts.append(f"kernels per call: XLA {_count(oj)} (fused), PyTorch eager {_count(ot)} ATen operators")
    if how:
        parts.append(how)
    text = "; ".join(parts)
    return text if "thread" in text else f"{text}; threads: PyTorch {TORCH_THREADS}, XLA default ({os.cpu_count()} cores)"


DISPATCH_BOUND_S = 2e-3  # a call shorter than this is mostly per-operator dispatch (~10 us x 100s of ops)


def _generic_note(op: str, ratio: float, batch=None, call_s=None, torch_threads=None, torch_mode=None) -> str:
    """Reason for a ratio beyond 2x where no batch fit exists: from the batch, the slower framework's
    call time (call_s, seconds) and the kind of operation. torch_threads: the PyTorch row's own thread
    count where it chose one (else the study's TORCH_THREADS); torch_mode: its mode where not eager."""
    what = ("PyTorch faster" if ratio < 1 else "JAX faster") + f" {max(ratio, 1 / ratio):.1f}x"
    chosen = " (the faster of 1 and all cores)" if torch_threads is not None else ""
    threads = (f"PyTorch on {TORCH_THREADS if torch_threads is None else torch_threads} thread(s){chosen}, "
               f"XLA's pool default ({os.cpu_count()} cores)")
    if op.startswith("train"):
        return (f"{what}: eager autograd runs forward and backward operator by operator plus a per-parameter "
                f"Adam, against one fused, compiled XLA step; {threads}")
    if op.startswith("matmul") or "GFLOP/s" in op:
        return f"{what}: matrix products at these shapes; {threads}"
    at = f"batch {batch}" if batch is not None else "this size"
    compiled = torch_mode not in (None, "eager")
    if call_s is not None and call_s < DISPATCH_BOUND_S:
        why = (f"PyTorch {torch_mode} is one call into a compiled library, JAX one dispatch of its program"
               if compiled else "eager PyTorch dispatches every operator from Python")
        return f"{what}: {at}, the slower call takes {call_s * 1e6:.3g} us: per-call and per-operator dispatch dominates ({why})"
    if call_s is None and batch is not None and batch < 256:
        return f"{what}: {at}, small batch: per-call dispatch overhead likely dominates (no call time given)"
    slow = f" (slower call {call_s:.3g} s)" if call_s is not None else ""
    if compiled:
        return (f"{what}: {at}{slow}, compute-bound, both compiled (PyTorch {torch_mode}: AOTInductor's C++ "
                f"kernels around ATen's matrix products, against XLA's fused program); {threads}")
    return (f"{what}: {at}{slow}, compute-bound: XLA fuses the elementwise work into the products' loops, "
            f"PyTorch eager runs each operator separately; {threads}")


def _row(op, j, t, kind, batch=None, note=None, torch_threads=None, torch_mode=None, dof=None):
    """j, t: throughputs (per second); with a batch, the slower call time is batch / min(j, t). `kind` and
    `dof` are the row's structured key (`KINDS`; the targets select rows by them, never by `operation`)."""
    r = j / t if (np.isfinite(j) and np.isfinite(t) and t > 0) else np.nan
    beyond = np.isfinite(r) and not 0.5 <= r <= 2.0
    call_s = batch / min(j, t) if batch is not None and beyond else None
    text = ((note if note is not None else _generic_note(op, r, batch, call_s, torch_threads, torch_mode))
            if beyond else "")
    return {"operation": op, "kind": kind, "dof": dof, "jax": j, "torch": t, "ratio": r, "note": text}


def _pairs(rows, keys, value):
    got: dict = {}
    for r in rows:
        got.setdefault(tuple(r[k] for k in keys), {})[r["framework"]] = r[value]
    return {k: v for k, v in got.items() if "jax" in v and "torch" in v}


def _latency_ratios(latency) -> list[dict]:
    """One row per (method, dtype): the fastest JAX single-sample mode against the fastest PyTorch one."""
    out = []
    for (meth, dt) in sorted({(r["method"], r["dtype"]) for r in latency}):
        rs = [r for r in latency if r["method"] == meth and r["dtype"] == dt]
        jx = [r for r in rs if r["framework"] == "jax"]
        tc = [r for r in rs if r["framework"] == "torch"]
        if not jx or not tc:
            continue
        j, t = max(jx, key=lambda r: r["evals_per_s"]), max(tc, key=lambda r: r["evals_per_s"])
        eager = next((r for r in tc if r["mode"] == "eager"), t)
        how = ("one call into the AOTInductor library" if t["mode"] == "compile_single" else
               f"{_count(t.get('ops'))} ATen operators each dispatched from Python")
        note = (f"one sample, JAX {j['mode']} ({j['dispatch']} dispatch): {_us(1 / j['evals_per_s'])} per call, "
                f"{_count(j.get('ops'))} XLA kernels in one dispatch; PyTorch {t['mode']}: {_us(1 / t['evals_per_s'])} "
                f"per call, {how} (eager: {_us(1 / eager['evals_per_s'])}, {_count(eager.get('ops'))} ATen operators)")
        out.append(_row(f"single sample delan {meth} {dt} (evals/s)", j["evals_per_s"], t["evals_per_s"],
                        "latency", batch=1, note=note))
    return out


def fastest_mode(fastpaper) -> list[dict]:
    """The fast/paper rows with one row per (dof, framework, formulation): the fastest of its modes (PyTorch
    eager, aoti, traced)."""
    best: dict = {}
    for r in fastpaper:
        k = (r["dof"], r["framework"], r["formulation"])
        if k not in best or r["samples_per_s"] > best[k]["samples_per_s"]:
            best[k] = r
    return list(best.values())


def ratio_rows(inference, training, scaling, fastpaper, matmul, notes, latency=()) -> list[dict]:
    out = _latency_ratios(latency)
    fastpaper = fastest_mode(fastpaper)
    inf = fastest_per_batch([r for r in inference if r.get("source") == "random_init"])
    fit = _fit_call_cost(inf)
    ops = {(r["system"], r["model"], r["formulation"], r["dtype"], r["framework"]): r.get("ops") for r in inf
           if r.get("mode") not in ("aoti", "traced")}
    used = {(r["system"], r["model"], r["formulation"], r["dtype"], r["batch"]): r for r in inf
            if r["framework"] == "torch"}
    paired = paired_best([r for r in inference if r.get("source") == "random_init"])
    for (sy, m, f, dt, b), v in _pairs(inf, ("system", "model", "formulation", "dtype", "batch"),
                                      "samples_per_s").items():
        tr, within = used[(sy, m, f, dt, b)], "the fastest of its modes and thread counts at this batch"
        if (sy, m, f, dt, b) in paired:  # both sides from the same interleaved rounds
            tr = paired[(sy, m, f, dt, b)]
            v = {"jax": tr["jax_paired_samples_per_s"], "torch": tr["samples_per_s"]}
            within = "its best mode and thread count against JAX timed in the same interleaved rounds"
        how = (f"threads: PyTorch {tr['threads']} ({tr.get('mode', 'eager')}, {within}), XLA default "
               f"({os.cpu_count()} cores)" if "threads" in tr else "")
        note = _inference_note((sy, m, f, dt), b, v["jax"], v["torch"], fit, ops, how) if v["torch"] > 0 else None
        out.append(_row(f"q'' {sy} {m}/{f} {dt} batch {b}", v["jax"], v["torch"], "inference", batch=b, note=note))
    jit = {(r["model"], r["batch"]): r["steps_per_s"] for r in training if r["mode"] == "jit"}
    for r in training:
        if r["framework"] == "torch" and (r["model"], r["batch"]) in jit:
            out.append(_row(f"train {r['system']} {r['model']} jit vs {r['mode']} batch {r['batch']} (steps/s)",
                            jit[r["model"], r["batch"]], r["steps_per_s"], "training"))
    batch_of = {(r["study"], r["formulation"], r["n"]): r.get("batch") for r in scaling}
    for (st, f, n), v in _pairs(scaling, ("study", "formulation", "n"), "samples_per_s").items():
        out.append(_row(f"scaling {st} {f} n={n}", v["jax"], v["torch"], "scaling", batch=batch_of.get((st, f, n))))
    for (d, f), v in _pairs(fastpaper, ("dof", "formulation"), "samples_per_s").items():
        out.append(_row(f"q'' lnn/{f} d={d} float32 batch {fastpaper[0]['batch']} (3x600 target)",
                        v["jax"], v["torch"], "fast_paper", batch=fastpaper[0]["batch"], dof=d,
                        torch_threads=_threads_of(fastpaper, dof=d, framework="torch", formulation=f),
                        torch_mode=_mode_of(fastpaper, dof=d, framework="torch", formulation=f)))
    for d in sorted({r["dof"] for r in fastpaper}):
        sp = {fw: row_value(fastpaper, dof=d, framework=fw, formulation="fast") /
              row_value(fastpaper, dof=d, framework=fw, formulation="paper") for fw in ("jax", "torch")}
        tgt = TARGETS["fast_over_paper"].get(d)
        out.append({"operation": f"fast/paper speedup d={d}", "kind": "fast_over_paper", "dof": d,
                    "jax": sp["jax"], "torch": sp["torch"],
                    "ratio": np.nan, "note": f"target >= {tgt}" if tgt else ""})
    for d in sorted({r["dof"] for r in matmul}):
        mm = {fw: row_value(matmul, "gflops", dof=d, framework=fw) for fw in ("jax", "torch")}
        flops = row_value(fastpaper, "flops_per_sample", dof=d, framework="jax", formulation="fast")
        ach = {fw: flops * row_value(fastpaper, dof=d, framework=fw, formulation="fast") / 1e9 for fw in mm}
        out.append(_row(f"matmul roofline: matrix products of the layer shapes d={d} (GFLOP/s)", mm["jax"], mm["torch"],
                        "matmul", torch_threads=_threads_of(matmul, dof=d, framework="torch"), dof=d))
        out.append(_row(f"fast LNN achieved d={d} (GFLOP/s; {flops:.3g} FLOP/sample from XLA cost analysis)",
                        ach["jax"], ach["torch"], "achieved", dof=d,
                        torch_threads=_threads_of(fastpaper, dof=d, framework="torch", formulation="fast"),
                        torch_mode=_mode_of(fastpaper, dof=d, framework="torch", formulation="fast")))
        out.append({"operation": f"fast LNN fraction of roofline d={d}", "kind": "roofline_fraction", "dof": d,
                    "jax": ach["jax"] / mm["jax"],
                    "torch": ach["torch"] / mm["torch"], "ratio": np.nan,
                    "note": "target >= 0.8 (JAX); each framework against its own matrix-product rate"})
    out += [{"operation": "note", "kind": "note", "dof": None, "jax": np.nan, "torch": np.nan, "ratio": np.nan, "note": n}
            for n in notes]
    return out


def _threads_of(rows, **match):
    """The `threads` a matching row chose (int), or None where it has none (results from before the column)."""
    t = row_value(rows, "threads", **match)
    return int(t) if np.isfinite(t) else None


def _mode_of(rows, **match):
    """The `mode` of the first matching row, or None (eager rows from before the column)."""
    return next((r.get("mode") for r in rows if all(r.get(k) == v for k, v in match.items())), None)


def row_value(rows, value="samples_per_s", **match):
    """The first matching row's value as a float; NaN where no row matches or the row has no value."""
    for r in rows:
        if all(r.get(k) == v for k, v in match.items()):
            v = r.get(value)
            return np.nan if v is None or v == "" else float(v)
    return np.nan
