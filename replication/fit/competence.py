"""Whether a fitted model learned anything: its error against the null predictor's (the better of predicting
zero and predicting the mean target), on the set the fit reports.

`competence(metrics, metric) -> dict | None`: {"metric", "value", "null", "ratio" (value / null), "factor",
"learned" (ratio <= FACTOR), "verdict"} for a metric "<set>_<loss>" whose null ("null_<set>_<loss>") was
recorded, else None. A ratio above FACTOR is not clearly better than the null; at or above 1 it is no better.
`describe(c) -> str`: the one line the command prints and the report shows.
"""
from __future__ import annotations

FACTOR = 0.5   # "clearly better than the null": at most half its error (the claims' competence bar asks 0.1)


def competence(metrics: dict, metric: str) -> dict | None:
    value, null = metrics.get(metric), metrics.get(f"null_{metric}")
    if value is None or null is None or not null > 0:
        return None
    ratio = value / null
    verdict = ("learned" if ratio <= FACTOR else
               "not clearly better than the null predictor" if ratio < 1 else "no better than the null predictor")
    return {"metric": metric, "value": value, "null": null, "ratio": ratio, "factor": FACTOR,
            "learned": ratio <= FACTOR, "verdict": verdict}


def describe(c: dict) -> str:
    text = f"{c['ratio']:.3g} x the null predictor's {c['null']:.4g}"
    if c["learned"]:
        return text
    return (f"{text}: {c['verdict'].upper()} (predicting zero or the mean does as well or nearly; see "
            f"docs/fit.md, 'Did it learn?')")
