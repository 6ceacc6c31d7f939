"""Claim 6 (LNN Appendix C): the empirical initialisation trains faster than standard inits.

Same LNN and double-pendulum data as claims 1-2; one model per init scheme. Which init reaches a good
Lagrangian is decided more by the seed than by the scheme (of 8 cranmer2020 inits scouted for claims 1-2,
one or two reach the competence bar, the others stop at a held-out L1 of 13-18; measured), so the claim is
judged over many seeds, each seed's run its own init and batches, trained side by side as one vectorised
program (`Protocol.cohort`): the samples each run took to leave the q-double-dot ~ 0 plateau (training
loss at most half the null predictor's held-out L1, `eval_pace`; +inf if not within the budget), compared
between inits by a one-sided Mann-Whitney test (`rules.faster`); the share that left, with its Wilson
interval, and the share that reached the competence bar are reported beside.

quick: 8 seeds of the claims 1-2 scouts' protocol (3 x 64, batch 32, peak 1e-3, velocity inputs x 0.3,
the spike guard) for `pace_study.PACE_STEPS` steps; full: 16 seeds for the scouts' whole 15 625 steps.
"""
from lagbench.replication.claims import double_pendulum as dp
from lagbench.replication.claims import pace_study as pace
from lagbench.replication.claims.bars import Bar
from lagbench.replication.claims.base import Claim, ModelEntry, Part
from lagbench.replication.claims.rules import faster

INITS = ("cranmer2020", "xavier", "kaiming", "pytorch_default")
SMOKE_INITS = ("cranmer2020", "kaiming")   # smoke: two cohorts of two seeds, to keep the test run short
MODELS = tuple(ModelEntry(f"lnn_init-{i}", {"kind": "lnn", "activation": "softplus", "init": i,
                                             "angle_wrap": True}, hidden=pace.WIDTHS, profile_spec=dp.VELOCITY_SCALE,
                          profiles=("smoke", "quick", "full", "paper") if i in SMOKE_INITS else ("quick", "full", "paper"))
               for i in INITS)

CLAIM = Claim(
    id="init_study", number=6, paper="LNN", section="Appendix C",
    title="The empirical initialisation trains faster than standard initialisations",
    system="double_pendulum", models=MODELS, protocols=pace.PROTOCOLS, evaluate="pace",
    metric="left_plateau", metric_label=pace.METRIC_LABEL,
    published={},
    verdict_rule="cranmer2020 leaves the plateau in fewer samples than each other init (a part each): the "
                 "Hodges-Lehmann ratio's exact two-sided interval at 0.05 / 3 below 1 (above 1: that init is faster)",
    parts=tuple(Part(f"faster than {m.label.split('-', 1)[1]}", faster("lnn_init-cranmer2020", m.label, len(MODELS) - 1),
                     reads=("lnn_init-cranmer2020", m.label)) for m in MODELS[1:]),
    bars=(Bar(("lnn_init-cranmer2020",), "heldout_l1", fraction=pace.LEFT),),
    seeds=pace.SEEDS, pooled=True,
)
