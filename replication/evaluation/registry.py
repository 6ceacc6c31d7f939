"""The registry of evaluation routines that claims name, and the version of what they compute
(`EVALUATION_VERSION`, defined in `replication.evaluation.version`, which says when to raise it)."""
from lagbench.replication.evaluation.arm import eval_arm
from lagbench.replication.evaluation.control import eval_control
from lagbench.replication.evaluation.exact import eval_exact_lagrangian
from lagbench.replication.evaluation.online_claim import eval_online
from lagbench.replication.evaluation.pace import eval_pace
from lagbench.replication.evaluation.precision import eval_precision
from lagbench.replication.evaluation.routines import eval_energy_rollout, eval_heldout
from lagbench.replication.evaluation.short_rollout import eval_heldout_trajectories
from lagbench.replication.evaluation.version import EVALUATION_VERSION
from lagbench.replication.evaluation.wave import eval_wave
from lagbench.replication.fit.evaluate import eval_fit

EVALUATIONS = {"heldout": eval_heldout, "heldout_trajectories": eval_heldout_trajectories, "pace": eval_pace,
               "energy_rollout": eval_energy_rollout, "wave": eval_wave,
               "arm": eval_arm, "exact_lagrangian": eval_exact_lagrangian,
               "precision": eval_precision, "fit": eval_fit, "control": eval_control,
               "online": eval_online}
__all__ = ["EVALUATIONS", "EVALUATION_VERSION"]
