"""The registry of evaluation routines that claims name, and the version of what they compute.

`EVALUATION_VERSION` is recorded in every unit's result.json; a unit evaluated under another version
is not current (the runner re-evaluates it, reusing its cached training). Raise it whenever a routine
changes what a metric means or adds one a verdict reads."""
from replication.eval_arm import eval_arm
from replication.eval_exact import eval_exact_lagrangian
from replication.eval_pace import eval_pace
from replication.eval_precision import eval_precision
from replication.eval_wave import eval_wave
from replication.evaluate import eval_energy_rollout, eval_heldout
from replication.fit_evaluate import eval_fit

# 2: null-predictor metrics for the competence bars; diverged rollouts count as +inf in the energy means
EVALUATION_VERSION = 2

EVALUATIONS = {"heldout": eval_heldout, "pace": eval_pace, "energy_rollout": eval_energy_rollout, "wave": eval_wave,
               "arm": eval_arm, "exact_lagrangian": eval_exact_lagrangian,
               "precision": eval_precision, "fit": eval_fit}
