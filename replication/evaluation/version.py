"""The version of what the evaluation routines compute (`EVALUATION_VERSION`), in a module of its own so that
the claims' registration (`replication.claims.registration`, read by the report) can fingerprint it without
importing the routines.

It is recorded in every unit's result.json; a unit evaluated under another version is not current (the runner
re-evaluates it, reusing its cached training), and it is part of every claim's registered protocol, so a
change of what a metric means is a new registration. Raise it whenever a routine changes what a metric means
or adds one a verdict reads.

- 2: null-predictor metrics for the competence bars; diverged rollouts count as +inf in the energy means
- 3: valid prediction time, the chaos floor's from a 1e-8 perturbation and the Lyapunov time (energy rollouts)
- 4: an HNN on canonical (q, p) rolled out by its own H (energy and short rollouts)
- 5: its velocity is the true system's at each predicted state (q, p) (the inverse of the momentum map, not
  M(q)^-1 p), so its energy is H_true(q, p); the energy's median and quartiles over initial conditions
"""
EVALUATION_VERSION = 5
