"""Claim 11 (hard case "float32 against float64"): what the precision changes on the double pendulum.

The original code ran everything in float32, its ground truth included (adaptive RK45 at an unattainable
rtol = atol = 1e-10): that truth's own final energy drift over 40 ICs to t = 100 was 0.10 % on average,
1.96 % at worst (reference §4, measured). This claim trains the double-pendulum baseline and LNN in float32
and in float64 (same init numbers, same batches) and reports held-out L1, the energy error against the
float64 truth, and the ground truth's own energy drift when integrated in each dtype (`eval_precision`).

Models: the double-pendulum claims' own (`double_pendulum.MODELS`: their widths, input scaling, spike guard
and the widths `lagbench tune` chose for them), so that only the dtype differs between a pair. In `smoke`,
`full` and `paper` they train under the double-pendulum claims' protocols (`full` under quick's), so the
float32 models are claim 1's, read from the training cache. In `quick`, the preliminary profile, the check
has a protocol of its own (`QUICK`): the continuation's one-cycle alone, for a tenth of the double pendulum's
budget, without restarts; a float64 baseline under claim 1's protocol would be a third of quick's time, and a
numerics check needs a model that has learned, not claim 1's accuracy. In `quick` and `full` the baseline
alone: a float64 LNN would cost about 3x its float32 training in JAX. The LNN joins at `paper` scale.
The reference's 0.10 % float32 truth drift is measured on the original code, not published: it is
context in the module docstring, not a published value.
"""
from lagbench.replication.claims import double_pendulum as dp
from lagbench.replication.claims.bars import Bar
from lagbench.replication.claims.base import Claim, ModelEntry, Part
from lagbench.replication.claims.rules import better_by, similar
from lagbench.replication.claims.seed_rule import PRELIMINARY_SEEDS

L1_CHANGE = 0.5   # learned-model held-out L1 may change by less than this fraction between dtypes


def _entries():
    out = []
    for m in dp.MODELS:
        # the LNN at paper scale only (see above); smoke and quick: the baseline
        profiles = ("paper",) if m.label == "lnn" else ("smoke", "quick", "full", "paper")
        for dtype in ("float32", "float64"):
            # full runs quick's protocol, so quick's widths too (the full dp models are 3 x 128)
            out.append(ModelEntry(f"{m.label}_{dtype.replace('float', 'f')}", m.spec,
                                  hidden={**m.hidden, "full": m.hidden["quick"]},
                                  profile_spec=m.profile_spec, overrides={"dtype": dtype}, profiles=profiles))
    return tuple(out)


MODELS = _entries()
# quick: the double pendulum's continuation (batch 256, one-cycle at peak 1e-2 from phase 0.1, the spike guard)
# from a fresh init, for 1.1e6 samples (a tenth of claim 1's quick budget), no restarts and no tracking
QUICK = dp.RESTARTS.replace(steps=1_100_000 // 256, scouting=None, tracking=None)
PROTOCOLS = {"smoke": dp.PROTOCOLS["smoke"], "quick": QUICK, "full": dp.RESTARTS,
             "paper": dp.PROTOCOLS["paper"]}   # full: claim 1's quick protocol, on the reference's horizon (EVAL)
# full and paper: the reference's horizon, 40 initial conditions to t = 100
REFERENCE_HORIZON = {**dp.EVAL["paper"], "truth_integrator": "dopri5", "truth_tol": 1e-10}
EVAL = {
    "smoke": {**dp.EVAL["smoke"], "truth_integrator": "rk4"},
    "quick": {**dp.EVAL["quick"], "n_ics": 10, "t_end": 5.0, "n_t": 51, "truth_integrator": "dopri5", "truth_tol": 1e-10},
    "full": REFERENCE_HORIZON, "paper": REFERENCE_HORIZON,
}


# the float64 truth drifts less (read on the baseline's units: the truth is the same for every model of a
# dtype), and each model's held-out L1 changes by less than L1_CHANGE between the dtypes (a part per model)
PARTS = (Part("float64 truth drifts less", better_by("baseline_f64", "baseline_f32", 1.0, "truth_energy_drift_final"),
              reads=("baseline_f64", "baseline_f32")),
         *(Part(f"{m.label} held-out L1 independent of dtype",
                similar(f"{m.label}_f64", f"{m.label}_f32", 1.0 + L1_CHANGE, "heldout_l1"),
                reads=(f"{m.label}_f64", f"{m.label}_f32")) for m in dp.MODELS))
CLAIM = Claim(
    id="precision", number=11, paper="LNN", section="§5 code (float32 truth); SPEC hard cases",
    title="float64 removes the ground truth's own energy drift; learned-model errors barely depend on dtype",
    system="double_pendulum", models=MODELS, protocols=PROTOCOLS, evaluate="precision",
    metric="truth_energy_drift_final",
    metric_label="ground truth's own |E(T) - E(0)| / 29.4 integrated in the model's dtype, mean over ICs "
                 "(same truth for every model of a dtype)",
    published={},
    verdict_rule=f"truth drift float64 < float32 over the 90 % interval of the seeds, and each model's held-out L1 f64/f32 "
                 f"within {1 + L1_CHANGE:g}x (a part each)",
    parts=PARTS, kind="check", bars=(Bar(tuple(m.label for m in MODELS), "heldout_l1"),),
    key="baseline_f32", eval_config=EVAL, seeds={"smoke": 1, "quick": PRELIMINARY_SEEDS, "full": 3, "paper": 3},
)
