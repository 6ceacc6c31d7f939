"""lagbench: the replication suite for learned Lagrangian and Hamiltonian dynamics, under one name.

    lagbench.systems      SymPy ground truth, code generation, trajectories and datasets
    lagbench.models       the framework-neutral model spec and parameters; jax/ and torch/ mirrors
    lagbench.replication  training, evaluation, claims and verdicts, the unit runner, fitting a user's data
    lagbench.reports      tables, figures, markdown and PDF, from result files only
    lagbench.speedstudy   the speed study
    lagbench.files        the ground floor: result files, the folder lock, loading a user's function
    lagbench.cli          the command line, above every package (`lagbench`, `python -m lagbench`)

An installed wheel holds the five subpackages inside this folder (pyproject's package-directory mapping); a
source checkout keeps them at the top of the repository, so there this package's search path also holds the
checkout's root and `lagbench.systems` names the same files either way.
"""
import os as _os
from pathlib import Path as _Path

_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # busy-waiting OpenMP threads stall a loaded CPU (CONTRIBUTING)

_checkout = _Path(__file__).resolve().parent.parent
if not (_Path(__file__).resolve().parent / "systems").is_dir() and (_checkout / "systems" / "__init__.py").is_file():
    __path__.append(str(_checkout))
