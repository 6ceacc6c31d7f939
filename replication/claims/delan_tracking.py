"""Claim 12 (DeLaN §5, control): computed-torque tracking with DeLaN's learned inverse model beats the
feed-forward net's, on references neither trained on.

The DeLaN paper's experiment: each learned inverse model gives the feed-forward torque of a computed-torque
controller of the simulated two-link arm at 500 Hz (`replication.evaluation.control`). The models are claim
9's full-data DeLaN and feed-forward net, trained once for both claims (the same entries, protocols and
adopted tuning: the training cache serves both). Unseen references (the test family) and the training family
played twice as fast are a part each; the competence bar asks each learned controller to track new references
of its training family with at most half the squared error of PD alone (the null controller), so that a model
that did not learn its inverse dynamics decides nothing. The true inverse dynamics' error (the best any
model gives) is recorded beside every unit. The paper prints tracking only as figures on its own
trajectories: no number to compare with.
"""
from lagbench.replication.claims import two_link_arm as arm
from lagbench.replication.claims.bars import Bar
from lagbench.replication.claims.base import Claim, Part
from lagbench.replication.claims.rules import better_by

MODELS = tuple(m for m in arm.MODELS if m.label in ("delan", "ff"))
METRIC = "tracking_mse_test"
# references per family and seconds each: smoke keeps a short loop, the others the control study's 8 x 4 s
EVAL = {"smoke": {"n_refs": 2, "duration": 0.5}, "quick": {"n_refs": 8, "duration": 4.0},
        "full": {"n_refs": 8, "duration": 4.0}, "paper": {"n_refs": 8, "duration": 4.0}}
CLAIM = Claim(
    id="delan_tracking", number=12, paper="DeLaN", section="§5, tracking control of the 2-link arm",
    title="DeLaN's inverse model tracks unseen and faster references better than a feed-forward net's",
    system="two_link_arm", models=MODELS, protocols=arm.PROTOCOLS, evaluate="control",
    metric=METRIC, metric_label="tracking MSE of the joint angles (rad^2) on unseen (test-family) references, "
                                "computed-torque control at 500 Hz",
    published={},
    verdict_rule="delan / ff < 1 in tracking MSE on unseen references and on the training family twice as fast "
                 "(a part each), over the 90 % interval of the seeds",
    parts=(Part("unseen references", better_by("delan", "ff", 1.0, METRIC), reads=("delan", "ff")),
           Part("references twice as fast", better_by("delan", "ff", 1.0, "tracking_mse_train_x2"),
                reads=("delan", "ff"))),
    bars=(Bar(("delan", "ff"), "tracking_mse_train", fraction=0.5),),
    seeds=arm.SEEDS, eval_config=EVAL,
)
