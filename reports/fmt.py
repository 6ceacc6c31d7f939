"""Formatting of numbers and cells: every cell becomes a non-empty string.

``num(x)`` gives 3 significant digits (``"0.0731"``, ``"4.3e-04"``); ``stat(mean, std, n)`` gives
``"0.0731 ± 0.002 (n=3)"``; ``cell(x)`` turns None/NaN/"" into ``"not run"`` (or a given placeholder).
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
    x = float(x)
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    if x == 0:
        return "0"
    if 1e-3 <= abs(x) < 1e5:
        return f"{x:.{digits}g}"
    return f"{x:.{digits - 1}e}"


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
