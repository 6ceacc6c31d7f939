"""Claim 2 (LNN §5, Fig. 4): the LNN conserves energy far better than the baseline.

Same trained models as claim 1 (the training cache shares them); the metric is the original one:
|E_pred(T) - E_true(T)| / 29.4 at the final time, averaged over initial conditions near rest.
"""
from replication.claims import double_pendulum as dp
from replication.claims.base import Claim, ratio_rule

CLAIM = Claim(
    id="dp_energy", number=2, paper="LNN", section="§5, Fig. 4",
    title="LNN conserves energy far better than the baseline on the double pendulum",
    system="double_pendulum", models=dp.MODELS, protocols=dp.PROTOCOLS, evaluate="energy_rollout",
    metric="energy_err_final", metric_label="|E_pred(T) - E_true(T)| / 29.4, mean over initial conditions",
    published={"lnn": 0.0043, "baseline": 0.0736},
    verdict_rule="lnn * 3 < baseline (partly: lnn < baseline)", verdict=ratio_rule("lnn", "baseline", 3.0),
    eval_config=dp.EVAL, seeds=dp.SEEDS,
)
