"""Replication report from result files alone: ``build_report(results_dir, out_dir) -> dict``.

Reads the files described in ``replication/RESULTS.md`` (plus ``bench/``) with pandas/NumPy, draws
figures with matplotlib and typesets the PDF with typst. Never imports jax, torch, equinox, optax,
diffrax, or the suite's ``systems``, ``models`` or ``replication`` packages.
"""

from reports.build import build_report

__all__ = ["build_report"]
