"""Users' data files for `lagbench fit`: loading, validation, and the train / held-out split.

Accepted: `.npz` with arrays q, qdot, qddot (each (N, d)) and optionally tau (N, d); or `.csv` with
columns q0..q{d-1}, qdot0.., qddot0.. and optionally tau0... Every problem (unknown suffix, missing
or extra-short columns, mismatched lengths, non-finite values, too few rows) raises a ValueError
that names it. The split is a fixed random 10 % held out (seed 0), the same for every model.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

REQUIRED = ("q", "qdot", "qddot")


def _from_csv(path):
    import pandas as pd

    try:
        df = pd.read_csv(path)
    except Exception as e:
        raise ValueError(f"{path}: cannot read as CSV ({e})") from e
    out = {}
    for name in (*REQUIRED, "tau"):
        cols = sorted((c for c in df.columns if c.startswith(name) and c[len(name):].isdigit()),
                      key=lambda c: int(c[len(name):]))
        if cols:
            try:
                out[name] = df[cols].to_numpy(dtype=np.float64)
            except (TypeError, ValueError) as e:
                raise ValueError(f"{path}: columns {', '.join(cols)} are not all numbers ({e})") from e
    return out


def _from_npz(path):
    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: np.asarray(z[k], dtype=np.float64) for k in z.files if k in (*REQUIRED, "tau")}
    except Exception as e:
        raise ValueError(f"{path}: cannot read as .npz ({e})") from e


@lru_cache(maxsize=4)
def load(path: str) -> dict:
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"data file {path} does not exist")
    if p.suffix not in (".csv", ".npz"):
        raise ValueError(f"{path}: unsupported file type {p.suffix!r}; use .npz or .csv")
    d = _from_csv(p) if p.suffix == ".csv" else _from_npz(p)
    missing = [k for k in REQUIRED if k not in d]
    if missing:
        hint = "columns q0.., qdot0.., qddot0.." if p.suffix == ".csv" else "arrays q, qdot, qddot"
        raise ValueError(f"{path}: missing {', '.join(missing)} (expected {hint}, optional tau)")
    for k, v in d.items():
        if v.ndim == 1:
            d[k] = v = v[:, None]
        if v.ndim != 2:
            raise ValueError(f"{path}: {k} must be (N, d), got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            bad = int(np.sum(~np.all(np.isfinite(v), axis=1)))
            raise ValueError(f"{path}: {k} has {bad} rows with NaN or infinite values")
    shapes = {k: v.shape for k, v in d.items()}
    if len(set(shapes.values())) != 1:
        raise ValueError(f"{path}: mismatched shapes {shapes}; every array must be (N, d) with the same N and d")
    if len(d["q"]) < 20:
        raise ValueError(f"{path}: only {len(d['q'])} rows; need at least 20 (10 % are held out)")
    return d


def split_rows(path: str, task: str, kind: str) -> dict:
    d = load(path)
    n = len(d["q"])
    idx = np.random.default_rng(0).permutation(n)
    cut = max(1, n // 10)
    rows = idx[:cut] if kind == "heldout" else idx[cut:]
    q, qdot, qddot = d["q"][rows], d["qdot"][rows], d["qddot"][rows]
    if task == "inverse_dynamics":
        return {"q": q, "qdot": qdot, "extra": qddot, "target": d["tau"][rows], "qddot": qddot}
    if task == "hamiltonian":
        return {"q": q, "qdot": qdot, "target": np.concatenate([qdot, qddot], 1), "qddot": qddot}
    return {"q": q, "qdot": qdot, "target": qddot, "qddot": qddot}
