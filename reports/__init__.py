"""Replication report from result files alone: ``build_report(results_dir, out_dir) -> dict``.

Reads the files described in ``docs/RESULTS.md`` (plus ``bench/``) with pandas/NumPy, draws
figures with matplotlib and typesets the PDF with typst. Never imports jax, torch, equinox, optax,
diffrax, the suite's ``systems``, its ``models`` beyond their NumPy parameter layout (``models.params``, which
counts a unit's parameters from its recorded spec), or its training and evaluation code; from
``replication`` it takes only the claim records and ``replication.claims.verdicts.judge`` (NumPy and pandas),
so that its verdicts are the runner's own rule applied to the unit files it reads.
"""

from lagbench.reports.build import build_report

__all__ = ["build_report"]
