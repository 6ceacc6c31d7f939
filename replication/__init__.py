"""The replication, a folder per job: training/ (protocols, the one loop, JAX and PyTorch steps), evaluation/,
claims/ (records, rules, verdicts), run/ (units, runner, executors), fit/ (a user's data), studies/, and the
`lagbench` command line (cli.py). Result files: results.py, layout in docs/RESULTS.md."""
import os as _os

_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # busy-waiting OpenMP threads stall a loaded CPU (CONTRIBUTING)
