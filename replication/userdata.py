"""Users' data files for `lagbench fit`: loading, validation, and the train / held-out split.

Accepted: `.npz` with arrays q, qdot, qddot (each (N, d)) and optionally tau (N, d); or `.csv` with
columns q0..q{d-1}, qdot0.., qddot0.. and optionally tau0... (spaces around header names are
ignored). Every problem (unknown suffix, missing columns or a gap in their numbering, mismatched
lengths, non-finite values or values beyond the training dtype's range, too few rows) raises a
ValueError that names it. The split is a fixed random 10 % held out (seed 0), the same for every model.

Content addressing: a file is read once into bytes, hashed (sha256) and parsed from those bytes;
`reference(path, digest)` is what a protocol records (`file:<path>#sha256=<hex>`), so the training
cache key and the unit's result change whenever the file's bytes do, and `split_rows` refuses a
file whose bytes no longer match the recorded hash. Parsed files are kept in memory by hash, never
by path alone.
"""
from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np

from replication.results import sha256_bytes

REQUIRED = ("q", "qdot", "qddot")
_MARK = "#sha256="
_PARSED: dict = {}  # (suffix, sha256) -> parsed arrays; a few entries


def reference(path: str, digest: str) -> str:
    """The protocol's `data` field for a user file: its path and the sha256 of its bytes."""
    return f"file:{path}{_MARK}{digest}"


def parse_reference(ref: str) -> tuple[str, str | None]:
    """(path, sha256 or None) from `reference`'s text, with or without the "file:" prefix."""
    ref = ref.removeprefix("file:")
    path, mark, digest = ref.rpartition(_MARK)
    if mark and re.fullmatch(r"[0-9a-f]{64}", digest):
        return path, digest
    return ref, None


def _columns(path, df, name) -> list:
    cols = sorted((c for c in df.columns if c.startswith(name) and c[len(name):].isdigit()),
                  key=lambda c: int(c[len(name):]))
    found = [int(c[len(name):]) for c in cols]
    if found and found != list(range(len(found))):
        raise ValueError(f"{path}: columns {', '.join(cols)} must be numbered {name}0..{name}{len(found) - 1} "
                         f"without gaps or repeats")
    return cols


def _from_csv(path, raw: bytes):
    import pandas as pd

    try:
        df = pd.read_csv(io.BytesIO(raw))
    except Exception as e:
        raise ValueError(f"{path}: cannot read as CSV ({e})") from e
    df.columns = [str(c).strip() for c in df.columns]
    out = {}
    for name in (*REQUIRED, "tau"):
        cols = _columns(path, df, name)
        if cols:
            try:
                out[name] = df[cols].to_numpy(dtype=np.float64)
            except (TypeError, ValueError) as e:
                raise ValueError(f"{path}: columns {', '.join(cols)} are not all numbers ({e})") from e
    return out


def _from_npz(path, raw: bytes):
    try:
        with np.load(io.BytesIO(raw), allow_pickle=False) as z:
            return {k: np.asarray(z[k], dtype=np.float64) for k in z.files if k in (*REQUIRED, "tau")}
    except Exception as e:
        raise ValueError(f"{path}: cannot read as .npz ({e})") from e


def read(path: str) -> tuple[str, dict]:
    """(sha256 of the file's bytes, its validated arrays), parsed from one read of the file."""
    p = Path(path)
    if p.suffix not in (".csv", ".npz"):
        raise ValueError(f"{path}: unsupported file type {p.suffix!r}; use .npz or .csv")
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise FileNotFoundError(f"data file {path} does not exist") from None
    except OSError as e:
        raise ValueError(f"data file {path}: cannot read ({e.strerror or e})") from None
    digest = sha256_bytes(raw)
    key = (p.suffix, digest)
    if key not in _PARSED:
        if len(_PARSED) >= 4:
            _PARSED.pop(next(iter(_PARSED)))
        _PARSED[key] = _validate(p, _from_csv(p, raw) if p.suffix == ".csv" else _from_npz(p, raw))
    return digest, _PARSED[key]


def load(path: str, sha256: str | None = None) -> dict:
    """The validated arrays of `path`; with `sha256`, only if the file still has exactly those bytes."""
    digest, d = read(path)
    if sha256 is not None and digest != sha256:
        raise ValueError(f"data file {path} changed since this fit was set up (sha256 {digest[:12]}..., "
                         f"recorded {sha256[:12]}...); run `lagbench fit` again")
    return d


def check_range(path, d: dict, dtype: str) -> None:
    """Every value must be finite in the training dtype (1e300 is finite in float64, inf in float32)."""
    big = float(np.finfo(dtype).max)
    for k, v in d.items():
        bad = int(np.sum(np.any(np.abs(v) > big, axis=1)))
        if bad:
            raise ValueError(f"{path}: {k} has {bad} rows with values beyond the {dtype} range (|x| > {big:.3g})")


def _validate(p: Path, d: dict) -> dict:
    path = str(p)
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


def split_rows(ref: str, task: str, kind: str) -> dict:
    """The train or held-out rows of the file `ref` names (a path, or `reference`'s text without "file:")."""
    d = load(*parse_reference(ref))
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
