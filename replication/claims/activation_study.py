"""Claim 7 (LNN §4 / Appendix): softplus beats ReLU^2, ReLU^3, tanh and sigmoid; plain ReLU cannot
work (its second derivative is zero, so the velocity Hessian vanishes).

Judged as claim 6 is (`init_study`): each activation over many seeds trained side by side, the samples
each run took to leave the q-double-dot ~ 0 plateau compared by a one-sided Mann-Whitney test; plain ReLU
must stay more than 3x softplus's held-out L1 (it cannot leave: its velocity Hessian is zero).
"""
from replication.claims import double_pendulum as dp
from replication.claims import init_study
from replication.claims.base import Claim, ModelEntry
from replication.claims.rules import all_parts, fails, faster

ACTS = ("softplus", "relu2", "relu3", "tanh", "sigmoid", "relu")
SMOKE_ACTS = ("softplus", "tanh", "relu")   # smoke: the reference, one smooth rival and plain ReLU
MODELS = tuple(ModelEntry(f"lnn_act-{a}", {"kind": "lnn", "activation": a, "init": "cranmer2020",
                                            "angle_wrap": True}, hidden=init_study.W,
                          profile_spec=dp.VELOCITY_SCALE,
                          profiles=("smoke", "quick", "paper") if a in SMOKE_ACTS else ("quick", "paper"))
               for a in ACTS)


SMOOTH = tuple(f"lnn_act-{a}" for a in ACTS if a not in ("softplus", "relu"))

CLAIM = Claim(
    id="activation_study", number=7, paper="LNN", section="§4, activation functions",
    title="Softplus beats ReLU^2, ReLU^3, tanh, sigmoid; plain ReLU cannot work",
    system="double_pendulum", models=MODELS, protocols=init_study.PROTOCOLS, evaluate="pace",
    metric="left_plateau", metric_label="share of seeds off the q-double-dot ~ 0 plateau after a fixed budget",
    published={},
    verdict_rule="softplus leaves the plateau in fewer samples than every other smooth activation (one-sided "
                 "Mann-Whitney over seeds, p < 0.05 / 4) and relu's held-out L1 > 3x softplus's, seed ranges "
                 "apart (partly: some of it)",
    verdict=all_parts(faster("lnn_act-softplus", SMOOTH),
                      fails("lnn_act-relu", ("lnn_act-softplus",), 3.0, "heldout_l1")),
    seeds=init_study.SEEDS, pooled=True,
)
