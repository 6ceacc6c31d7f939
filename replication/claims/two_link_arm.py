"""The two-link arm's models and protocols, shared by claim 9 (torque prediction, `delan_arm`) and claim 12
(tracking control, `delan_tracking`), which train the same full-data models once.

Protocol after the original PyTorch example (reference delan §3): 2 x 64 softplus, batch 512,
Adam lr 5e-4, weight decay 1e-5 (as an L2 term), torque MSE; trained on one family of smooth
trajectories. Data efficiency: the same models on smaller pools (`SIZES`), each a few points along several
trajectories (`replication.training.data.arm_trajectories`), trained for as many steps as the full pool.
"""
from lagbench.replication.claims.base import ModelEntry
from lagbench.replication.claims.seed_rule import PRELIMINARY_SEEDS
from lagbench.replication.training.protocol import Data, Protocol
from lagbench.replication.training.schedules import Constant

W = {"smoke": (16, 16), "quick": (64, 64), "full": (64, 64), "paper": (64, 64)}
_delan = {"kind": "delan", "activation": "softplus", "init": "xavier"}
_ff = {"kind": "baseline", "activation": "softplus", "init": "xavier", "extra_inputs": 2}
SIZES = {"smoke": (), "quick": (256, 1024), "full": (256, 1024), "paper": (128, 512, 2048)}


def _models():
    out = [ModelEntry("delan", _delan, hidden=W), ModelEntry("ff", _ff, hidden=W)]
    for n in sorted({n for v in SIZES.values() for n in v}):
        prof = {p: {"data.n_train": n, "batch": min(n, 256)} for p, v in SIZES.items() if n in v}
        out.append(ModelEntry(f"delan_n{n}", _delan, hidden=W, overrides=prof, profiles=tuple(prof)))
        out.append(ModelEntry(f"ff_n{n}", _ff, hidden=W, overrides=prof, profiles=tuple(prof)))
    return tuple(out)


MODELS = _models()
_data = Data("two_link_arm", n_train=512, n_heldout=512)
_base = Protocol(data=_data, task="inverse_dynamics", steps=20, batch=32, loss="mse", l2=1e-5,
                 schedule=Constant(lr=5e-4), log_every=5)
# quick: 8000 steps for every pool: at 2000 the small pools were under-trained (JAX, 3 seeds, torque MSE on the
# training family's held-out states against the null's 34.7: DeLaN n256 3.9 -> 0.22 at 8000, FF n256 5.0 -> 3.2),
# and every pool gets the same steps, so that only the data differ
QUICK = _base.replace(steps=8000, batch=256, data=_data.replace(n_train=4096, n_heldout=4000), log_every=200,
                      schedule=Constant(lr=1e-3))
PROTOCOLS = {"smoke": _base, "quick": QUICK, "full": QUICK,   # full runs quick's protocol
             "paper": _base.replace(steps=40_000, batch=512, data=_data.replace(n_train=2459, n_heldout=4000), log_every=500)}
SEEDS = {"smoke": 1, "quick": PRELIMINARY_SEEDS, "full": 5, "paper": 5}
