"""Claim 2 (LNN §5, Fig. 2(b)): the LNN conserves energy far better than the baseline.

Same trained models as claim 1 (the training cache shares them); the metric is the original one:
|E_pred(T) - E_true(T)| / 29.4 at the final time, averaged over initial conditions near rest, a
diverged rollout counting as +inf. Both models must have learned (claim 1's bar) and the LNN's
rollouts must not diverge; a diverging baseline is what the claim predicts.
"""
from replication.claims import double_pendulum as dp
from replication.claims.bars import Bar
from replication.claims.base import Claim, Part
from replication.claims.published import Published
from replication.claims.rules import better_by

_PAPER_HORIZON = (("n_ics", 40), ("t_end", 100.0))
# the rollouts also give the float32 floor of the valid prediction time (the exact model in float32); no
# verdict reads it
EVAL = {p: {**cfg, "float32_truth": True} for p, cfg in dp.EVAL.items()}
CLAIM = Claim(
    id="dp_energy", number=2, paper="LNN", section="§5, Fig. 2(b)",
    title="LNN conserves energy far better than the baseline on the double pendulum",
    system="double_pendulum", models=dp.MODELS, protocols=dp.PROTOCOLS, evaluate="energy_rollout",
    metric="energy_err_final",
    metric_label="|E_pred(T) - E_true(T)| / 29.4, mean over initial conditions (diverged = +inf)",
    published={
        "lnn": Published(0.0043, "rollout energy error at the final time", "LNN paper §5; code cell 48: "
                         "40 ICs near rest to t = 100", metric="energy_err_final", conditions=_PAPER_HORIZON),
        "baseline": Published(0.0736, "rollout energy error at the final time", "LNN paper §5; code Baseline "
                              "cell 49: 44 ICs to t = 100 (the 44th froze)", metric="energy_err_final",
                              conditions=(("n_ics", 44), ("t_end", 100.0)))},
    verdict_rule="lnn / baseline < 1/3 for every pair of seeds",
    parts=(Part("energy conservation", better_by("lnn", "baseline", 3.0, "energy_err_final"),
                reads=("lnn", "baseline")),),
    bars=(dp.LEARNED, Bar(("lnn",), None, max_diverged=0)),
    eval_config=EVAL, seeds=dp.SEEDS,
)
