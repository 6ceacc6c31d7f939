"""Claim 7 (LNN §4 / Appendix): softplus beats ReLU^2, ReLU^3, tanh and sigmoid; plain ReLU cannot
work (its second derivative is zero, so the velocity Hessian vanishes)."""
from replication.claims import init_study
from replication.claims.bars import Bar
from replication.claims.base import Claim, ModelEntry
from replication.claims.rules import all_parts, fails, lowest

ACTS = ("softplus", "relu2", "relu3", "tanh", "sigmoid", "relu")
MODELS = tuple(ModelEntry(f"lnn_act-{a}", {"kind": "lnn", "activation": a, "init": "cranmer2020",
                                            "angle_wrap": True}, hidden=init_study.W) for a in ACTS)


SMOOTH = tuple(f"lnn_act-{a}" for a in ACTS if a not in ("softplus", "relu"))

CLAIM = Claim(
    id="activation_study", number=7, paper="LNN", section="§4, activation functions",
    title="Softplus beats ReLU^2, ReLU^3, tanh, sigmoid; plain ReLU cannot work",
    system="double_pendulum", models=MODELS, protocols=init_study.PROTOCOLS, evaluate="heldout",
    metric="heldout_l1", metric_label="held-out L1 after a fixed short budget",
    published={},
    verdict_rule="softplus lowest of the smooth ones and relu > 3x softplus, seed ranges apart "
                 "(partly: one of the two)",
    verdict=all_parts(lowest("lnn_act-softplus", SMOOTH, "heldout_l1"),
                      fails("lnn_act-relu", ("lnn_act-softplus",), 3.0, "heldout_l1")),
    # plain relu is expected not to learn; among the smooth ones at least one must have
    bars=(Bar(("lnn_act-softplus", *SMOOTH), "heldout_l1", need="any"),),
    seeds={"smoke": 1, "quick": 3, "paper": 3},
)
