"""The replication: protocols, the mirrored JAX and PyTorch training loops, the claims, evaluation,
the resumable runner and the `lagbench` command line. Result files: see RESULTS.md beside this file."""
import os as _os

_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # busy-waiting OpenMP threads stall a loaded CPU (CONTRIBUTING)
