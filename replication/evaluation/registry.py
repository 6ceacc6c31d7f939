"""The registry of evaluation routines that claims name, and the version of what they compute.

`EVALUATION_VERSION` is recorded in every unit's result.json; a unit evaluated under another version
is not current (the runner re-evaluates it, reusing its cached training). Raise it whenever a routine
changes what a metric means or adds one a verdict reads."""
from replication.evaluation.arm import eval_arm
from replication.evaluation.control import eval_control
from replication.evaluation.exact import eval_exact_lagrangian
from replication.evaluation.online_claim import eval_online
from replication.evaluation.pace import eval_pace
from replication.evaluation.precision import eval_precision
from replication.evaluation.routines import eval_energy_rollout, eval_heldout
from replication.evaluation.short_rollout import eval_heldout_trajectories
from replication.evaluation.wave import eval_wave
from replication.fit.evaluate import eval_fit

# 2: null-predictor metrics for the competence bars; diverged rollouts count as +inf in the energy means
# 3: valid prediction time, the chaos floor's from a 1e-8 perturbation and the Lyapunov time (energy rollouts)
# 4: an HNN on canonical (q, p) rolled out by its own H, its velocity dH/dp (energy and short rollouts)
EVALUATION_VERSION = 4

EVALUATIONS = {"heldout": eval_heldout, "heldout_trajectories": eval_heldout_trajectories, "pace": eval_pace,
               "energy_rollout": eval_energy_rollout, "wave": eval_wave,
               "arm": eval_arm, "exact_lagrangian": eval_exact_lagrangian,
               "precision": eval_precision, "fit": eval_fit, "control": eval_control,
               "online": eval_online}
