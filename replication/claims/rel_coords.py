"""Claim 3 (LNN §5, relativistic particle): an HNN on the non-canonical (q, qdot) fails; an HNN on
canonical (q, p) and an LNN on (q, qdot) succeed.

Original protocol (reference §5): L = (1-qdot^2)^(-1/2) - 1 + g q, q ~ U[-10, 10], field g ~ N(0, 10^2)
given as an input, qdot = 0.99999 tanh(2 N(0,1)); 4x500 softplus; L1 weighted by 1 + gamma; Adam with
one-cycle, peak 1e-3; q and g divided by 10 at the input (the canonical HNN does not scale q).
The HNNs are trained on [qdot, pdot] (non-canonical: pdot := qdot-double-dot; canonical: the exact
pdot = dL/dq from `systems`). The original code put the canonical HNN's loss on q-double-dot, not pdot
(a finding). The verdict reads the weighted L1 of q-double-dot for all three (the canonical HNN's pdot
mapped through dp/dqdot).
Departures (see MODELS and PROTOCOLS): the models on (q, qdot) also see the Lorentz factor of qdot, the LNN
sees q unscaled, and quick trains every model with restarts at peak 1e-2 (the canonical HNN at 3e-3, on q / 10
and p / 100: CANONICAL_RATE). The original's LNN on qdot alone
runs beside (`lnn_qdot_only`, its own rate, no restarts; in smoke and paper), outside the verdict.
"""
from replication.claims.bars import Bar
from replication.claims.base import Claim, ModelEntry
from replication.claims.published import Published
from replication.claims.rules import fails
from replication.training.protocol import Protocol

W = {"smoke": (16, 16), "quick": (128, 128, 128), "paper": (500, 500, 500, 500)}
# The models on (q, qdot) see the velocity also through its Lorentz factor gamma = (1 - qdot^2)^(-1/2)
# (`ModelSpec.lorentz_factor`, scaled by 0.01: gamma reaches 224 here), a departure from the original, which
# fed qdot alone. Without it our LNN stays on the q-double-dot ~ 0 plateau even after 6.1e7 samples (the
# original's 4 x 500 left it after 5.8e7; `docs/relativistic_lnn_trials.md`): the weighted L1 pins every near-c
# prediction to 0 until the velocity Hessian grows like (1 - qdot^2)^(-5/2), which gamma's own curvature
# gives at once. gamma is kinematics (c), not the answer: with it the LNN also learns the standard
# Lagrangian -1/gamma + g q, which it cannot on qdot alone (measured, same budget: 0.080 against 0.70, null
# 0.71). The HNN on (q, qdot) gets it too, so the coordinates are all that differs; its failure is
# structural (its field (qdot, qdd) has divergence g r'(qdot) != 0: no H in these coordinates has it).
# The LNN sees q unscaled: q / 10 shrinks the g q coupling it must build (with gamma, 1500 steps at 1e-2, no
# restarts, seeds 0-2: 0.41 / 0.29 / 0.097 with q / 10, 0.0024 / 0.39 / 0.0077 unscaled). The original's LNN (qdot alone, q / 10) runs beside as `lnn_qdot_only`, context
# outside the verdict.
ORIGINAL = {"lr": 1e-3, "scouts": 0, "scout_steps": 0, "scout_lr": 0.0}   # lnn_qdot_only: the original's rate, no restarts
# In quick and full the canonical HNN sees p / 100 (p = gamma qdot spans +-224 like gamma, which the models on
# (q, qdot) see at 0.01) and q / 10, and trains (scouts and continuation) at peak 3e-3, not 1e-2. Measured (JAX, held-out weighted
# q-double-dot L1, seeds 0-2): quick 0.013 / 0.012 / 0.019 with (q, p, g) scaled (1, 1, 0.1) at 1e-2; 0.0070 /
# 0.0071 / 0.0066 with p / 100; 0.0063 / 0.0041 / 0.0047 with q / 10 too; 0.0038 / 0.0030 / 0.0030 at 3e-3
# (PyTorch 0.0032 / 0.0023 / 0.0033); at 1e-3 (p unscaled) 0.026 / 0.020 / 0.019. full: 0.0062 / 0.0057 / 0.0051
# at 1e-2, 0.0033 / 0.0024 / 0.0026 at 3e-3 (1e-2 unscaled: 0.016-0.017).
CANONICAL_RATE = {"lr": 3e-3, "scout_lr": 3e-3}
LORENTZ = {"lorentz_factor": True, "extra_inputs": 1, "activation": "softplus"}
MODELS = (
    ModelEntry("lnn", {"kind": "lnn", "init": "cranmer2020", "input_scale": (1.0, 1.0, 0.01, 0.1), **LORENTZ},
               hidden=W),
    ModelEntry("hnn_qqdot", {"kind": "hnn", "init": "xavier", "input_scale": (0.1, 1.0, 0.01, 0.1), **LORENTZ},
               hidden=W, overrides={"task": "hamiltonian", "coords": "qqdot"}),
    ModelEntry("lnn_qdot_only", {"kind": "lnn", "activation": "softplus", "init": "cranmer2020", "extra_inputs": 1,
                                 "input_scale": (0.1, 1.0, 0.1)}, hidden=W, overrides=ORIGINAL,
               profiles=("smoke", "paper")),   # not in quick (~130 s of its units) nor full (~1 300 s of worker time)
    ModelEntry("hnn_qp", {"kind": "hnn", "activation": "softplus", "init": "xavier", "extra_inputs": 1,
                          "input_scale": (1.0, 1.0, 0.1)}, hidden=W,
               overrides={"task": "hamiltonian", "coords": "qp", "quick": CANONICAL_RATE},
               profile_spec={"quick": {"input_scale": (0.1, 0.01, 0.1)}}),   # and full; paper: the original's
)

_base = Protocol(data="relativistic_iid", steps=20, batch=32, n_train=640, n_heldout=512, loss="l1_gamma",
                 lr=1e-3, schedule="onecycle", lr_start=0.3, log_every=5)
_SRC = "original code, SpecialRelativity notebooks, weighted-L1 training loss: "
PROTOCOLS = {
    "smoke": _base,
    # restarts over initialisations at a ten times higher rate, for every model alike: 8 scouts x 200 steps
    # at 1e-2, the best by training loss continued 1500 steps at 1e-2 (one-cycle). Measured (JAX, the LNN
    # with gamma, 1500 steps at 1e-2 without scouts): held-out 0.0024 / 0.39 / 0.0077 on seeds 0-2; at 1e-3
    # every seed stayed on the plateau
    "quick": _base.replace(steps=1500, batch=256, n_train=256 * 400, n_heldout=20_000, log_every=50, track_every=100,
                           lr=1e-2, scouts=8, scout_steps=200, scout_lr=1e-2),
    "paper": _base.replace(steps=300_000, batch=512, n_train=512 * 3000, n_heldout=100_000, log_every=1000),
}
# full: 13x quick's continuation, judged on 1e5 held-out states. On qdot alone (lnn_qdot_only): the original LNN sat on the
# q-double-dot ~ 0 plateau (weighted L1 0.40-0.58) for 38 epochs, 5.8e7 samples, before it dropped; in our
# trials (JAX, 3 x 128, seed 0) it stayed at the null's 0.410 after 5.1e6 samples, with the original input
# scaling and with q unscaled, and after MSE warm-ups: the weighted L1 pulls every near-c prediction to 0
# (their targets are ~0 and their weights up to 224) until the velocity Hessian grows like (1-qdot^2)^(-5/2).
# full ran lnn_qdot_only until 2026-11-26: at 5.1e6 samples all six units sat at the null's 0.408 (JAX and PyTorch,
# seeds 0-2, at 5464581 and 93bb4cd), for about 1 300 s of worker time, a tenth of full's 4 h outside the verdict.
# It runs in paper, at the original's 1.5e8 samples, where leaving the plateau is possible.
PROTOCOLS["full"] = PROTOCOLS["quick"].replace(steps=20_000, n_heldout=100_000, log_every=500, track_every=2000)


CLAIM = Claim(
    id="rel_coords", number=3, paper="LNN", section="§5, special relativity",
    title="HNN fails on non-canonical (q, qdot); HNN on (q, p) and LNN on (q, qdot) succeed",
    system="relativistic", models=MODELS, protocols=PROTOCOLS, evaluate="heldout",
    metric="heldout_l1_qddot", metric_label="held-out (1+gamma)-weighted L1 of q-double-dot",
    published={
        "lnn": Published(7.86e-4, "training loss", _SRC + "LNN, epoch 99", metric="final_train_loss",
                         note="ours also sees gamma(qdot)"),
        "lnn_qdot_only": Published(7.86e-4, "training loss", _SRC + "LNN, epoch 99", metric="final_train_loss"),
        "hnn_qqdot": Published(0.4096, "training loss", _SRC + "HNN on (q, qdot), epoch 99; on [qdot, qdd] as ours",
                               metric="final_train_loss"),
        "hnn_qp": Published(2.40e-4, "training loss", _SRC + "HNN on (q, p), epoch 99; on [qdot, qdd], ours on "
                            "[qdot, pdot]", note="different target")},
    verdict_rule="hnn_qqdot > 10 x max(lnn, hnn_qp), seed ranges apart (partly: merely the worst)",
    verdict=fails("hnn_qqdot", ("lnn", "hnn_qp"), 10.0, "heldout_l1_qddot"),
    # the claim is that these two learn; hnn_qqdot is expected not to, so it has no bar
    bars=(Bar(("lnn", "hnn_qp"), "heldout_l1_qddot"),),
    seeds={"smoke": 1, "quick": 3, "paper": 3},
)
