"""The speed study's targets (declared in one table, `speedstudy.bounds.TARGETS`) checked against
the measured rows.

`targets(ratios, scaling_fit, scaling, inference, training, latency, train_target, members) -> dict`:
one entry per target with the measured values, the bound and `met` (targets.json).
  fast_over_paper:          the fast LNN formulation over the paper's, per d (both frameworks at least)
  roofline_fraction:        the fast LNN's share of the attainable matrix-product GFLOP/s (JAX)
  jax_over_torch:           the worst JAX/PyTorch inference throughput ratio (PyTorch within this of JAX)
  lgn_banded_exponent:      the banded LGN's cost exponent in the grid size n (at most)
  lgn_banded_over_dense:    the banded LGN over the dense one at n = 1024 (at least)
  delan_single_sample_per_s: DeLaN's best one-sample evaluations per second (at least)
  members_cost_vs_one:      8 members trained as one program over one model's wall time (at most)
  train_target:             held-out L1 <= the paper's 7.3e-2 within a tenth of the original's samples
"""
from __future__ import annotations

import numpy as np

from lagbench.speedstudy.bounds import TARGETS
from lagbench.speedstudy.members import MEMBERS, MODES
from lagbench.speedstudy.tables import fastest_per_batch, row_value
from lagbench.speedstudy.train_target import ORIGINAL_SAMPLES, PAPER_L1, TARGET_SAMPLES


def members_target(rows) -> dict:
    """{framework: wall time of MEMBERS members over one model's}, the bound and whether every framework meets
    it in one of its step modes at least; a mode other than a framework's first (`speedstudy.members.MODES`:
    PyTorch's torch.compile) is keyed `<framework>_<mode>`. Beside them, `<key>_one_at_k_batch`: one model at
    MEMBERS x the batch over one model (the same samples per step as the members), the floor that vectorising
    the members can reach; `floor_above_target` says whether a framework's lowest floor already exceeds the
    bound (then the bound is out of reach on this machine at this size, whatever the vectorising). Rows
    without a mode (speed studies before modes) count as the framework's first."""
    def key(r):
        first = MODES.get(r["framework"], (None,))[0]
        mode = r.get("mode") or first
        return r["framework"] if mode == first else f"{r['framework']}_{mode}"

    cost, floor, best, lowest = {}, {}, {}, {}   # best / lowest: per framework, over its modes
    base = {key(r): r["batch"] for r in rows if r["members"] == MEMBERS}
    for r in rows:
        fw, c = r["framework"], r["cost_vs_one"]
        if r["members"] == MEMBERS:
            cost[key(r)], best[fw] = c, min(c, best.get(fw, c))
        elif r["members"] == 1 and r["batch"] == MEMBERS * base.get(key(r), 0):
            floor[f"{key(r)}_one_at_k_batch"], lowest[fw] = c, min(c, lowest.get(fw, c))
    bound = TARGETS["members_cost_vs_one"]
    out = {**cost, **floor, "members": MEMBERS, "target": bound,
           "met": bool(cost) and max(best.values()) <= bound}
    if floor:
        out["floor_above_target"] = max(lowest.values()) > bound
    return out


def targets(ratios, scaling_fit, scaling, inference, training, latency=(), train_target=(), members=()) -> dict:
    t: dict = {}
    t.update(_fast_over_paper(ratios))
    t.update(_inference_within(ratios))
    t.update(_lgn(scaling_fit, scaling))
    t.update(_delan(inference, latency))
    t.update(_train_target(train_target))
    if members:
        t["members_cost_vs_one"] = members_target(members)
    one_batch = len({r["batch"] for r in training}) <= 1
    t["training_samples_per_s"] = {f"{r['model']}/{r['framework']}/{r['mode']}"
                                   + ("" if one_batch else f"/batch {r['batch']}"): r["samples_per_s"]
                                   for r in training}
    return t


def _of(ratios, kind) -> list[dict]:
    return [r for r in ratios if r["kind"] == kind]


def _fast_over_paper(ratios) -> dict:
    """The fast/paper speedups per d (both frameworks) and the fast LNN's share of the roofline (JAX)."""
    t = {}
    speedup = {r["dof"]: r for r in _of(ratios, "fast_over_paper")}
    for d, tgt in TARGETS["fast_over_paper"].items():
        r = speedup.get(d)
        if r:
            t[f"fast_over_paper_d{d}"] = {"jax": r["jax"], "torch": r["torch"], "target": tgt,
                                          "met": bool(r["jax"] >= tgt and r["torch"] >= tgt)}
    bound = TARGETS["roofline_fraction"]
    for r in _of(ratios, "roofline_fraction"):
        t[f"fast_LNN_fraction_of_roofline_d={r['dof']}"] = {"jax": r["jax"], "torch": r["torch"], "target": bound,
                                                            "met": bool(r["jax"] >= bound)}
    return t


def _inference_within(ratios) -> dict:
    """The worst JAX/PyTorch ratio over every q'' throughput both frameworks measured (the batched inference
    rows and the 3 x 600 fast/paper rows)."""
    inf_ratios = [r["ratio"] for r in _of(ratios, "inference") + _of(ratios, "fast_paper") if np.isfinite(r["ratio"])]
    if not inf_ratios:
        return {}
    bound = TARGETS["jax_over_torch"]
    return {"torch_within_1.5x_of_jax_inference": {"worst_jax_over_torch": max(inf_ratios), "n_ops": len(inf_ratios),
                                                   "n_beyond": sum(x > bound for x in inf_ratios),
                                                   "met": bool(max(inf_ratios) <= bound)}}


def _lgn(scaling_fit, scaling) -> dict:
    """The banded LGN's cost exponent in n, and its speedup over the dense one at n = 1024 (or the largest n)."""
    t = {}
    for r in scaling_fit:
        if r["study"] == "lgn_grid" and r["formulation"] == "banded":
            t[f"lgn_banded_exponent_{r['framework']}_{r.get('fit_range', 'all')}"] = {
                "exponent": r["exponent"], "n_min": r.get("n_min"), "n_max": r.get("n_max"),
                "target": TARGETS["lgn_banded_exponent"], "met": bool(r["exponent"] <= TARGETS["lgn_banded_exponent"])}
    for fw in ("jax", "torch"):
        ns = [r["n"] for r in scaling if r["study"] == "lgn_grid" and r["framework"] == fw]
        if not ns:
            continue
        n = 1024 if 1024 in ns else max(ns)
        sp = (row_value(scaling, study="lgn_grid", formulation="banded", framework=fw, n=n)
              / row_value(scaling, study="lgn_grid", formulation="dense", framework=fw, n=n))
        bound = TARGETS["lgn_banded_over_dense"]
        t[f"lgn_banded_over_dense_n{n}_{fw}"] = {"speedup": sp, "target": bound, "met": bool(sp >= bound)}
    return t


def _delan(inference, latency) -> dict:
    """DeLaN's best one-sample evaluations per second per framework, beside its batched rates."""
    t = {}
    bound = TARGETS["delan_single_sample_per_s"]
    for fw in ("jax", "torch"):
        dl = {r["batch"]: r["samples_per_s"] for r in fastest_per_batch(inference) if r["model"] == "delan" and
              r["framework"] == fw and r["dtype"] == "float32" and r["system"] == "double_pendulum"
              and r.get("source", "random_init") == "random_init"}
        single = {f"{r['method']}/{r['mode']}/{r['dispatch']}": r["evals_per_s"] for r in latency
                  if r["framework"] == fw and r["dtype"] == "float32"}
        if not (dl or single):
            continue
        best = max(single.items(), key=lambda kv: kv[1]) if single else (None, dl.get(1) or 0.0)
        t[f"delan_{fw}"] = {"single_sample_per_s": best[1], "best_mode": best[0], "single_sample": single,
                            "batched_acceleration": {str(b): v for b, v in dl.items()}, "target_single": bound,
                            "met": bool(best[1] >= bound), "met_by": sorted(k for k, v in single.items() if v >= bound)}
    return t


def _train_target(train_target) -> dict:
    """Per train-to-target protocol of the LNN: the samples to each threshold, met if the paper's L1 came
    within TARGET_SAMPLES."""
    t = {}
    for proto in sorted({r["protocol"] for r in train_target if r.get("model", "lnn") == "lnn"}):
        rs = sorted((r for r in train_target if r["protocol"] == proto), key=lambda r: -r["threshold"])
        paper = [r for r in rs if abs(r["threshold"] - PAPER_L1) < 1e-9]
        hit = bool(paper and np.isfinite(paper[0]["samples_to_reach"])
                   and paper[0]["samples_to_reach"] <= TARGET_SAMPLES)
        t[f"train_target_{proto}"] = {
            "target": f"held-out L1 <= {PAPER_L1:g} within {TARGET_SAMPLES:.0e} samples (a tenth of the original's "
                      f"{ORIGINAL_SAMPLES:.0e})", "budget": rs[0]["budget"], "hidden": rs[0]["hidden"],
            "best_l1": rs[0]["best_l1"], "description": rs[0]["description"],
            "hessian_rel_err": rs[0].get("hessian_rel_err", float("nan")),
            "samples_to_reach": {f"{r['threshold']:g}": r["samples_to_reach"] for r in rs},
            "extrapolated_samples_NOT_MEASURED": {f"{r['threshold']:g}": r["extrapolated_samples"] for r in rs},
            "met": hit}
    return t
