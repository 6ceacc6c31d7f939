"""Claim 3 (LNN §5, relativistic particle): an HNN on the non-canonical (q, qdot) fails; an HNN on
canonical (q, p) and an LNN on (q, qdot) succeed.

Original protocol (reference §5): L = (1-qdot^2)^(-1/2) - 1 + g q, q ~ U[-10, 10], field g ~ N(0, 10^2)
given as an input, qdot = 0.99999 tanh(2 N(0,1)); 4x500 softplus; L1 weighted by 1 + gamma; Adam with
one-cycle, peak 1e-3; q and g divided by 10 at the input (the canonical HNN does not scale q).
The HNNs are trained on [qdot, pdot] (non-canonical: pdot := qdot-double-dot). The verdict reads the
weighted L1 of q-double-dot for all three (the canonical HNN's pdot mapped through dp/dqdot).
"""
from replication.claims.base import Claim, ModelEntry
from replication.protocol import Protocol

W = {"smoke": (16, 16), "quick": (128, 128, 128), "paper": (500, 500, 500, 500)}
MODELS = (
    ModelEntry("lnn", {"kind": "lnn", "activation": "softplus", "init": "cranmer2020", "extra_inputs": 1,
                       "input_scale": (0.1, 1.0, 0.1)}, hidden=W),
    ModelEntry("hnn_qqdot", {"kind": "hnn", "activation": "softplus", "init": "xavier", "extra_inputs": 1,
                             "input_scale": (0.1, 1.0, 0.1)}, hidden=W,
               overrides={"task": "hamiltonian", "coords": "qqdot"}),
    ModelEntry("hnn_qp", {"kind": "hnn", "activation": "softplus", "init": "xavier", "extra_inputs": 1,
                          "input_scale": (1.0, 1.0, 0.1)}, hidden=W,
               overrides={"task": "hamiltonian", "coords": "qp"}),
)

_base = Protocol(data="relativistic_iid", steps=20, batch=32, n_train=640, n_heldout=512, loss="l1_gamma",
                 lr=1e-3, schedule="onecycle", lr_start=0.3, log_every=5)
PROTOCOLS = {
    "smoke": _base,
    "quick": _base.replace(steps=1500, batch=256, n_train=256 * 400, n_heldout=20_000, log_every=50),
    "paper": _base.replace(steps=300_000, batch=512, n_train=512 * 3000, n_heldout=100_000, log_every=1000),
}


def _verdict(v):
    lnn, bad, good = v.get("lnn"), v.get("hnn_qqdot"), v.get("hnn_qp")
    if None in (lnn, bad, good):
        return "not run", "missing a model"
    fails = bad > 10 * max(lnn, good)
    if fails:
        return "reproduced", f"hnn_qqdot {bad:.3g} > 10x max(lnn {lnn:.3g}, hnn_qp {good:.3g})"
    if bad > max(lnn, good):
        return "partly", f"hnn_qqdot {bad:.3g} worst, but within 10x (lnn {lnn:.3g}, hnn_qp {good:.3g})"
    return "not reproduced", f"hnn_qqdot {bad:.3g}, lnn {lnn:.3g}, hnn_qp {good:.3g}"


CLAIM = Claim(
    id="rel_coords", number=3, paper="LNN", section="§5, special relativity",
    title="HNN fails on non-canonical (q, qdot); HNN on (q, p) and LNN on (q, qdot) succeed",
    system="relativistic", models=MODELS, protocols=PROTOCOLS, evaluate="heldout",
    metric="heldout_l1_qddot", metric_label="held-out (1+gamma)-weighted L1 of q-double-dot",
    published={"lnn": 7.86e-4, "hnn_qqdot": 0.4096, "hnn_qp": 2.40e-4},
    verdict_rule="hnn_qqdot > 10 x max(lnn, hnn_qp) (partly: merely the worst)", verdict=_verdict,
    seeds={"smoke": 1, "quick": 2, "paper": 3},
)
