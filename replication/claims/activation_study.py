"""Claim 7 (LNN §4 / Appendix): softplus beats ReLU^2, ReLU^3, tanh and sigmoid; plain ReLU cannot
work (its second derivative is zero, so the velocity Hessian vanishes)."""
from replication.claims import init_study
from replication.claims.base import Claim, ModelEntry

ACTS = ("softplus", "relu2", "relu3", "tanh", "sigmoid", "relu")
MODELS = tuple(ModelEntry(f"lnn_act-{a}", {"kind": "lnn", "activation": a, "init": "cranmer2020",
                                            "angle_wrap": True}, hidden=init_study.W) for a in ACTS)


def _verdict(v):
    if "lnn_act-softplus" not in v:
        return "not run", "missing softplus"
    sp = v["lnn_act-softplus"]
    smooth = {k: x for k, x in v.items() if k not in ("lnn_act-softplus", "lnn_act-relu")}
    relu = v.get("lnn_act-relu")
    beats = all(sp < x for x in smooth.values())
    relu_fails = relu is None or relu > 3 * sp
    if beats and relu_fails:
        return "reproduced", f"softplus {sp:.3g} best; relu {relu if relu is None else f'{relu:.3g}'} fails"
    if beats or relu_fails:
        return "partly", f"softplus {sp:.3g}; " + ", ".join(f"{k} {x:.3g}" for k, x in v.items())
    return "not reproduced", ", ".join(f"{k} {x:.3g}" for k, x in v.items())


CLAIM = Claim(
    id="activation_study", number=7, paper="LNN", section="§4, activation functions",
    title="Softplus beats ReLU^2, ReLU^3, tanh, sigmoid; plain ReLU cannot work",
    system="double_pendulum", models=MODELS, protocols=init_study.PROTOCOLS, evaluate="heldout",
    metric="heldout_l1", metric_label="held-out L1 after a fixed short budget",
    published={m.label: None for m in MODELS},
    verdict_rule="softplus lowest of the smooth ones and relu > 3x softplus", verdict=_verdict,
    seeds={"smoke": 1, "quick": 2, "paper": 3},
)
