"""Formatting of numbers and cells: every cell becomes a non-empty string.

``num(x)`` gives 3 significant digits (``"0.0731"``, ``"447"``, ``"34500"``, ``"4.3e-04"``), an integer
(a Python or NumPy int) every digit (``"70311"``); ``count(x)`` an exact count, also of a float
(``"34,465"``: parameters, samples, steps, rows); ``stat(mean, std, n)`` gives
``"0.0731 ± 0.002 (n=3)"`` (± the sample standard deviation over n seeds); ``seed_values(values)`` gives the
seed mean with the range over seeds (``"0.0731 (0.0712 to 0.0750, 2 seeds)"``) or, for a yes/no metric
(every seed 0 or 1), ``"7/8 seeds"`` (an infinite value, a diverged rollout or a time never reached, counted
apart); ``seeds_words([3, 3])`` the seed counts in words; ``plain(x)`` a
nested record as text without braces (``"kind onecycle, lr 3.33e-04"``); ``cell(x)`` turns None/NaN/"" into
``"not run"`` (or a given placeholder).
"""

from __future__ import annotations

import math

import numpy as np

from lagbench.reports.document import NOT_RUN


def is_number(x) -> bool:
    return isinstance(x, int | float | np.integer | np.floating) and not isinstance(x, bool)


def num(x, digits: int = 3) -> str:
    if not is_number(x):
        return NOT_RUN if x is None else str(x)
    if isinstance(x, int | np.integer):   # a count or an index: every digit, never rounded nor in e-notation
        return str(int(x))
    x = float(x)
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    if x == 0:
        return "0"
    if 1e-3 <= abs(x) < 1e5:
        if abs(x) >= 10 ** (digits - 1):   # as many integer digits as significant ones: no exponent, no point
            return f"{round(x, digits - 1 - math.floor(math.log10(abs(x)))):.0f}"
        return f"{x:.{digits}g}"
    return f"{x:.{digits - 1}e}"


def count(x, missing: str = NOT_RUN) -> str:
    """An exact count (parameters, samples) with thousands separated: ``"34,465"``; `missing` without one."""
    return f"{int(round(float(x))):,}" if is_number(x) and math.isfinite(float(x)) else missing


def stat(mean, std=None, n=None) -> str:
    if not is_number(mean):
        return NOT_RUN
    text = num(mean)
    if is_number(std) and not math.isnan(float(std)) and (n is None or n > 1):
        text += f" ± {num(std, 2)}"
    if n is not None:
        text += f" (n={int(n)})"
    return text


def summarise(values: list[float]) -> dict:
    """mean, sample std (ddof=1; NaN for n=1) and count of finite values."""
    arr = np.asarray([v for v in values if v is not None], dtype=float)
    arr = arr[np.isfinite(arr)]
    if arr.size == 0:
        return {"mean": None, "std": None, "n": 0}
    std = float(arr.std(ddof=1)) if arr.size > 1 else float("nan")
    return {"mean": float(arr.mean()), "std": std, "n": int(arr.size)}


def cell(x, missing: str = NOT_RUN) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return missing
    if is_number(x):
        return num(x)
    text = str(x).strip()
    return text if text else missing


def label(metric: str) -> str:
    return metric.replace("_", " ")


def seed_values(values, share: bool = False) -> str:
    """The seed mean and the range over seeds (``"0.073 (0.071 to 0.075, 2 seeds)"``), a yes/no metric
    (``share``: each seed 0 or 1) as ``"7/8 seeds"``, a diverged seed (+inf) counted apart; "not run" without a
    value."""
    vals = [float(v) for v in values if v is not None and not math.isnan(float(v))]
    if not vals:
        return NOT_RUN
    if share and all(v in (0.0, 1.0) for v in vals):
        return f"{int(sum(vals))}/{len(vals)} seeds"
    finite = [v for v in vals if math.isfinite(v)]
    n_inf = len(vals) - len(finite)
    if not finite:
        return f"inf on {n_inf}/{len(vals)} seeds"
    text = (f"{num(finite[0])} (1 seed)" if len(finite) == 1 else
            f"{num(float(np.mean(finite)))} ({num(min(finite))} to {num(max(finite))}, {len(finite)} seeds)")
    return text + (f"; inf on {n_inf}/{len(vals)} seeds" if n_inf else "")


def seeds_words(counts) -> str:
    """``[2, 2]`` -> "2 seeds each"; ``[3, 2]`` -> "3 and 2 seeds"; ``[8]`` -> "8 seeds"."""
    counts = [int(c) for c in counts or []]
    if not counts:
        return "seeds not recorded"
    if len(set(counts)) == 1:
        n = counts[0]
        return f"{n} seed{'s' * (n != 1)}" + (" each" if len(counts) > 1 else "")
    return " and ".join(map(str, counts)) + " seeds"


def plain(x) -> str:
    """A value as text a table can hold: a record as "key value, ..." (nested records in parentheses), a list
    joined by commas, a number to 3 significant digits; never Python's braces."""
    if isinstance(x, dict):
        return ", ".join(f"{k} ({plain(v)})" if isinstance(v, dict) else f"{k} {plain(v)}" for k, v in x.items()) or "none"
    if isinstance(x, list | tuple):
        return ", ".join(plain(v) for v in x) or "none"
    if x is None:
        return "none"
    return num(x) if is_number(x) else str(x)

