"""Replication report from result files alone: ``build_report(results_dir, out_dir) -> dict``.

Reads the files described in ``docs/RESULTS.md`` (plus ``bench/``) with pandas/NumPy, draws
figures with matplotlib and typesets the PDF with typst. Never imports jax, torch, equinox, optax,
diffrax, the suite's ``systems``, its ``models`` beyond their NumPy parameter layout (``models.params``, which
counts a unit's parameters from its recorded spec), or its training and evaluation code; from
``replication`` it takes only the claim records, ``replication.claims.verdicts.judge`` and the rules a fit's
console line shares with it (``replication.evaluation.diverged``, ``replication.fit.competence``, ``rows.Overlap``;
NumPy and pandas), so that its verdicts and flags are the runner's own rules applied to the unit files it reads.
"""

from lagbench.reports.build import build_report

__all__ = ["build_report"]
