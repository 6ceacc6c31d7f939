"""Claim 11 (hard case "float32 against float64"): what the precision changes on the double pendulum.

The original code ran everything in float32, its ground truth included (adaptive RK45 at an unattainable
rtol = atol = 1e-10): that truth's own final energy drift over 40 ICs to t = 100 was 0.10 % on average,
1.96 % at worst (reference §4, measured). This claim trains the double-pendulum baseline and LNN in float32
and in float64 (same init numbers, same batches) and reports held-out L1, the energy error against the
float64 truth, and the ground truth's own energy drift when integrated in each dtype (`eval_precision`).

Budget (quick, about 3 min for both frameworks on 2 cores): one seed and a shortened dp protocol (600
steps, the step decay at 400, 2000 held-out states), shared by both dtypes so that only the dtype differs;
rollouts of 10 ICs to t = 5. The models are not the dp claims' (those train 4000 steps; their float32
cache cannot be shared without training float64 for as long, and float64 LNN training costs about 3x
float32 in JAX). At this scale the LNN is still on its q-double-dot ~ 0 plateau (held-out L1 ~ 47 in both
dtypes), so only the baseline's comparison is informative; the paper profile trains both fully.
"""
from replication.claims import double_pendulum as dp
from replication.claims.base import Claim, ModelEntry

L1_CHANGE = 0.5   # learned-model held-out L1 may change by less than this fraction between dtypes


def _entries():
    out = []
    for m in dp.MODELS:
        # smoke: the baseline only (an LNN's rollout compiles for ~15 s per unit in JAX)
        profiles = ("quick", "paper") if m.label == "lnn" else ("smoke", "quick", "paper")
        for dtype in ("float32", "float64"):
            out.append(ModelEntry(f"{m.label}_{dtype.replace('float', 'f')}", m.spec, hidden=m.hidden,
                                  overrides={"dtype": dtype}, profiles=profiles))
    return tuple(out)


MODELS = _entries()
PROTOCOLS = {
    "smoke": dp.PROTOCOLS["smoke"],
    "quick": dp.PROTOCOLS["quick"].replace(steps=600, n_train=128 * 150, n_heldout=2000, lr_step_every=400,
                                           log_every=50),
    "paper": dp.PROTOCOLS["paper"],
}
EVAL = {
    "smoke": {**dp.EVAL["smoke"], "truth_integrator": "rk4"},
    "quick": {**dp.EVAL["quick"], "t_end": 5.0, "n_t": 51, "truth_integrator": "dopri5", "truth_tol": 1e-10},
    "paper": {**dp.EVAL["paper"], "truth_integrator": "dopri5", "truth_tol": 1e-10},
}


def verdict(v):
    """v: {label: (truth_energy_drift_final, heldout_l1)} for one framework; judged on the models run
    in both dtypes (the smoke profile runs the baseline only)."""
    pairs = [m.label for m in dp.MODELS if f"{m.label}_f32" in v and f"{m.label}_f64" in v]
    if not pairs:
        return "not run", "no model ran in both float32 and float64"
    d32, d64 = v[f"{pairs[0]}_f32"][0], v[f"{pairs[0]}_f64"][0]
    truth_ok = d64 < d32
    changes = {k: abs(v[f"{k}_f64"][1] - v[f"{k}_f32"][1]) / max(v[f"{k}_f32"][1], 1e-300) for k in pairs}
    learned_ok = all(c < L1_CHANGE for c in changes.values())
    text = (f"truth drift float32 {d32:.3g} vs float64 {d64:.3g}; held-out L1 change f32->f64 "
            + ", ".join(f"{k} {c:.0%}" for k, c in changes.items()))
    if truth_ok and learned_ok:
        return "reproduced", text
    if truth_ok:
        return "partly", text + f" (a learned model changed by >= {L1_CHANGE:.0%})"
    return "not reproduced", text


CLAIM = Claim(
    id="precision", number=11, paper="LNN", section="§5 code (float32 truth); SPEC hard cases",
    title="float64 removes the ground truth's own energy drift; learned-model errors barely depend on dtype",
    system="double_pendulum", models=MODELS, protocols=PROTOCOLS, evaluate="precision",
    metric="truth_energy_drift_final",
    metric_label="ground truth's own |E(T) - E(0)| / 29.4 integrated in the model's dtype, mean over ICs "
                 "(same truth for every model of a dtype)",
    published={"lnn_f32": 0.0010, "baseline_f32": 0.0010},
    verdict_rule=f"truth drift float64 < float32, and each model's held-out L1 changes by < {L1_CHANGE:.0%} "
                 "between float32 and float64 (partly: only the truth part)",
    verdict=verdict, eval_config=EVAL, seeds={"smoke": 1, "quick": 1, "paper": 3},
    verdict_metrics=("truth_energy_drift_final", "heldout_l1"),
)
