"""Claim 7 (LNN §4 / Appendix): softplus beats ReLU^2, ReLU^3, tanh and sigmoid; plain ReLU cannot
work (its second derivative is zero, so the velocity Hessian vanishes).

Judged as claim 6 is (`init_study`): each activation over many seeds trained side by side, the samples
each run took to leave the q-double-dot ~ 0 plateau compared by a one-sided Mann-Whitney test, plain ReLU
among the rivals; and plain ReLU must leave it in no seed (`rules.never`): its velocity Hessian is zero, so
it cannot learn at all.
Why pace and not held-out L1 for ReLU: the study's budget is sized for the pace, not the end loss, and
softplus ends it half trained (held-out 20-27 against the null's 46.6 in quick), so an end-loss ordering would
measure the budget, not the claim; its bar asks only that softplus ends off the plateau (held-out L1 at most
half the null's). ReLU's held-out L1 there is the null's, 46.6 in every seed.
"""
from lagbench.replication.claims import double_pendulum as dp
from lagbench.replication.claims import pace_study as pace
from lagbench.replication.claims.bars import Bar
from lagbench.replication.claims.base import Claim, ModelEntry, Part
from lagbench.replication.claims.rules import faster, never

ACTS = ("softplus", "relu2", "relu3", "tanh", "sigmoid", "relu")
SMOKE_ACTS = ("softplus", "tanh", "relu")   # smoke: the reference, one smooth rival and plain ReLU
MODELS = tuple(ModelEntry(f"lnn_act-{a}", {"kind": "lnn", "activation": a, "init": "cranmer2020",
                                            "angle_wrap": True}, hidden=pace.WIDTHS,
                          profile_spec=dp.VELOCITY_SCALE,
                          profiles=("smoke", "quick", "full", "paper") if a in SMOKE_ACTS else ("quick", "full", "paper"))
               for a in ACTS)


RIVALS = tuple(f"lnn_act-{a}" for a in ACTS if a != "softplus")   # the smooth ones and plain ReLU

CLAIM = Claim(
    id="activation_study", number=7, paper="LNN", section="§4, activation functions",
    title="Softplus beats ReLU^2, ReLU^3, tanh, sigmoid; plain ReLU cannot work",
    system="double_pendulum", models=MODELS, protocols=pace.PROTOCOLS, evaluate="pace",
    metric="left_plateau", metric_label=pace.METRIC_LABEL,
    published={},
    verdict_rule="softplus leaves the plateau in fewer samples than each other activation, relu included (a part "
                 "each: the Hodges-Lehmann ratio's exact two-sided interval at 0.05 / 5 below 1), and relu leaves it "
                 "in no seed, with softplus, its positive control, past its bar",
    parts=(*(Part(f"faster than {r.split('-', 1)[1]}", faster("lnn_act-softplus", r, len(RIVALS)),
                  reads=("lnn_act-softplus", r)) for r in RIVALS),
           Part("plain ReLU cannot learn", never("lnn_act-relu"), reads=("lnn_act-relu",),
                controls=("lnn_act-softplus",))),
    bars=(Bar(("lnn_act-softplus",), "heldout_l1", fraction=pace.LEFT),),
    seeds=pace.SEEDS, pooled=True,
)
