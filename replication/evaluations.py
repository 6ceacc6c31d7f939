"""The registry of evaluation routines that claims name."""
from replication.eval_arm import eval_arm
from replication.eval_exact import eval_exact_lagrangian
from replication.eval_precision import eval_precision
from replication.eval_wave import eval_wave
from replication.evaluate import eval_energy_rollout, eval_heldout

EVALUATIONS = {"heldout": eval_heldout, "energy_rollout": eval_energy_rollout, "wave": eval_wave,
               "arm": eval_arm, "exact_lagrangian": eval_exact_lagrangian,
               "precision": eval_precision}
