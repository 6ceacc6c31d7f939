"""Importing a package imports no framework it does not need: the speed study's package and the reports
(which read result files only) load neither JAX nor PyTorch until something runs."""
import subprocess
import sys


def test_packages_import_no_framework():
    code = ("import sys, lagbench.replication, lagbench.reports, lagbench.speedstudy; "
            "print(','.join(m for m in ('torch', 'jax') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == ""
