"""Claim 9 (DeLaN §5): DeLaN learns the 2-link arm's inverse dynamics with lower torque error than a
feed-forward network, especially on unseen trajectories and with few samples; its mass matrix is
positive definite everywhere.

The models and protocols (`two_link_arm.py`, shared with claim 12) are trained on one family of smooth
trajectories and tested on another ("test" family); data efficiency reads the smaller pools. The competence
bar asks every model, the small-pool ones included, to have learned the training family (torque MSE on its
held-out states at most a tenth of the null's).
"""
from lagbench.replication.claims import two_link_arm as arm
from lagbench.replication.claims.bars import Bar
from lagbench.replication.claims.base import Claim, Part
from lagbench.replication.claims.published import Published
from lagbench.replication.claims.rules import better_by, bound

MODELS, PROTOCOLS, SIZES = arm.MODELS, arm.PROTOCOLS, arm.SIZES
METRIC = "torque_mse_test"
POOLS = sorted({n for v in SIZES.values() for n in v})


# DeLaN 3x below the FF net on unseen trajectories; below it at each pool size (a part each; a profile
# judges the pools it trains); its mass matrix positive definite: a check, since DeLaN's M = L L^T + eps I
# holds it for any weights, trained or not
PARTS = (Part("unseen trajectories", better_by("delan", "ff", 3.0, METRIC), reads=("delan", "ff")),
         *(Part(f"{n} training samples", better_by(f"delan_n{n}", f"ff_n{n}", 1.0, METRIC),
                reads=(f"delan_n{n}", f"ff_n{n}")) for n in POOLS),
         Part("mass matrix positive definite", bound("mass_matrix_min_eig", lower=0.0, models=("delan",)),
              reads=("delan",), check=True))
CLAIM = Claim(
    id="delan_arm", number=9, paper="DeLaN", section="§5, 2-link arm",
    title="DeLaN beats a feed-forward net on inverse dynamics, most on unseen trajectories and few samples",
    system="two_link_arm", models=MODELS, protocols=PROTOCOLS, evaluate="arm",
    metric=METRIC, metric_label="torque MSE on the unseen (test-family) trajectories",
    published={"delan": Published(4.3e-4, "torque MSE", "DeLaN repository README (PyTorch version), on its "
                                  "own character trajectories", metric=METRIC, other_data=True)},
    verdict_rule="delan / ff < 1/3 on unseen trajectories, delan / ff < 1 at each pool size (a part each), for "
                 "every pair of seeds; check: DeLaN's mass matrix positive definite",
    parts=PARTS,
    # learned on the training family (the unseen family is what the claim measures)
    bars=(Bar(("delan", "ff"), "torque_mse_train"),
          Bar(tuple(f"{m}_n{n}" for n in POOLS for m in ("delan", "ff")), "torque_mse_train")),
    seeds=arm.SEEDS,
)
