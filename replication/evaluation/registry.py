"""The registry of evaluation routines that claims name, and the version of what they compute
(`EVALUATION_VERSION`, defined in `replication.evaluation.version`, which says when to raise it)."""
from replication.evaluation.arm import eval_arm
from replication.evaluation.control import eval_control
from replication.evaluation.exact import eval_exact_lagrangian
from replication.evaluation.online_claim import eval_online
from replication.evaluation.pace import eval_pace
from replication.evaluation.precision import eval_precision
from replication.evaluation.routines import eval_energy_rollout, eval_heldout
from replication.evaluation.short_rollout import eval_heldout_trajectories
from replication.evaluation.version import EVALUATION_VERSION
from replication.evaluation.wave import eval_wave
from replication.fit.evaluate import eval_fit

EVALUATIONS = {"heldout": eval_heldout, "heldout_trajectories": eval_heldout_trajectories, "pace": eval_pace,
               "energy_rollout": eval_energy_rollout, "wave": eval_wave,
               "arm": eval_arm, "exact_lagrangian": eval_exact_lagrangian,
               "precision": eval_precision, "fit": eval_fit, "control": eval_control,
               "online": eval_online}
__all__ = ["EVALUATIONS", "EVALUATION_VERSION"]
