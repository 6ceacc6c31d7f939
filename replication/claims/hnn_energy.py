"""Claim 10 (HNN, as compared in both papers): an HNN conserves energy better than a baseline on the
mass-spring and the pendulum. HNN on canonical (q, p) with targets (qdot, pdot); baseline MLP
(q, qdot) -> qdd. Metric: max over the rollout of |E_pred - E_true| / scale, mean over initial states."""
from lagbench.replication.claims.bars import Bar
from lagbench.replication.claims.base import Claim, ModelEntry, Part
from lagbench.replication.claims.rules import better_by
from lagbench.replication.claims.seed_rule import PRELIMINARY_SEEDS
from lagbench.replication.training.protocol import Data, Protocol
from lagbench.replication.training.schedules import OneCycle

W = {"smoke": (16, 16), "quick": (128, 128), "full": (128, 128), "paper": (200, 200)}
_hnn = {"kind": "hnn", "activation": "tanh", "init": "xavier"}
_base_m = {"kind": "baseline", "activation": "tanh", "init": "xavier"}
HAM = {"task": "hamiltonian", "data.coords": "qp"}
MODELS = (ModelEntry("hnn_spring", _hnn, hidden=W, overrides={"data.recipe": "spring_iid", **HAM}),
          ModelEntry("baseline_spring", _base_m, hidden=W, overrides={"data.recipe": "spring_iid"}),
          ModelEntry("hnn_pendulum", _hnn, hidden=W, overrides={"data.recipe": "pendulum_iid", **HAM}),
          ModelEntry("baseline_pendulum", _base_m, hidden=W, overrides={"data.recipe": "pendulum_iid"}))
_data = Data("spring_iid", n_train=640, n_heldout=512)
_base = Protocol(data=_data, steps=20, batch=32, loss="mse", schedule=OneCycle(lr=1e-3), log_every=5)
QUICK = _base.replace(steps=2000, batch=128, data=_data.replace(n_train=128 * 200, n_heldout=5000), log_every=50)
PROTOCOLS = {"smoke": _base, "quick": QUICK, "full": QUICK,   # full runs quick's protocol
             "paper": _base.replace(steps=20_000, batch=256, data=_data.replace(n_train=256 * 500, n_heldout=20_000),
                                    log_every=500)}
QUICK_EVAL = {"n_ics": 10, "t_end": 30.0, "n_t": 301, "dt": 0.02, "energy_scale": 1.0}   # RK4 drift ~1e-6
EVAL = {"smoke": {"n_ics": 3, "t_end": 2.0, "n_t": 21, "dt": 0.01, "energy_scale": 1.0},
        "quick": QUICK_EVAL, "full": QUICK_EVAL,
        "paper": {"n_ics": 25, "t_end": 100.0, "n_t": 1000, "dt": 0.01, "energy_scale": 1.0}}


CLAIM = Claim(
    id="hnn_energy", number=10, paper="HNN", section="§3 (spring, pendulum)",
    title="HNN conserves energy better than a baseline on the mass-spring and the pendulum",
    system="spring, pendulum", models=MODELS, protocols=PROTOCOLS, evaluate="energy_rollout",
    metric="energy_err_max", metric_label="max_t |E_pred - E_true|, mean over initial states (diverged = +inf)",
    published={},
    verdict_rule="hnn / baseline < 1/3 over the 90 % interval of the seeds, on each system (a part each)",
    parts=tuple(Part(s, better_by(f"hnn_{s}", f"baseline_{s}", 3.0, "energy_err_max"), reads=(f"hnn_{s}", f"baseline_{s}"))
                for s in ("spring", "pendulum")),
    bars=(Bar(tuple(m.label for m in MODELS), "heldout_l1"),
          Bar(("hnn_spring", "hnn_pendulum"), None, max_diverged=0)),
    eval_config=EVAL, seeds={"smoke": 1, "quick": PRELIMINARY_SEEDS, "full": 5, "paper": 5},
)
