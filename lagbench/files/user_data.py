"""Users' data files for `lagbench fit`: loading, validation, and the train / held-out split.

Accepted: `.npz` with arrays q, qdot, qddot (each (N, d)) and optionally tau (N, d); or `.csv` with
columns q0..q{d-1}, qdot0.., qddot0.. and optionally tau0... (spaces around header names are
ignored; separated by commas, semicolons or tabs: the commonest of them in the header line, and a file
separated by semicolons or tabs whose rows hold commas has decimal commas). A *trajectory file* has a time column `t` (and optionally `traj`, the trajectory id): then
only q is required and the missing derivatives are estimated (`replication.fit.trajectories`). A prepared
file (`replication.fit.rows`, written by `lagbench fit`) adds a `split` column (train, heldout, test).
Every problem (unknown suffix, missing columns or a gap in their numbering, mismatched
lengths, non-finite values or values beyond the training dtype's range, too few rows) raises a
ValueError that names it; a row with a NaN or infinite value is named by its line in a CSV file (its
index in an .npz file) and its trajectory. Rows are split by the file's `split` column; a file without one (a state
file given straight to `split_rows`) by a fixed random 10 % held out (seed 0), the same for every model.

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

from lagbench.files.results import sha256_bytes

REQUIRED = ("q", "qdot", "qddot")
ARRAYS = (*REQUIRED, "tau")
COLUMNS = ("traj", "t", "split")  # single columns: trajectory id, time, and a prepared file's split
_MARK = "#sha256="
_LINES = "_lines"    # a CSV file's line number of each row, for naming a bad row
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


def content_only(obj):
    """`obj` (a protocol or an evaluation config, as plain data) with every user-file reference reduced to
    the sha256 of its bytes: what a fit's training key and its currency are compared on, so that moving a
    results folder or fitting a byte-identical copy under another name reuses the fit."""
    if isinstance(obj, dict):
        return {k: content_only(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [content_only(v) for v in obj]
    if isinstance(obj, str) and obj.startswith("file:"):
        _, digest = parse_reference(obj)
        if digest:
            return f"file:{_MARK}{digest}"
    return obj


def _columns(path, df, name) -> list:
    cols = sorted((c for c in df.columns if c.startswith(name) and c[len(name):].isdigit()),
                  key=lambda c: int(c[len(name):]))
    found = [int(c[len(name):]) for c in cols]
    if found and found != list(range(len(found))):
        raise ValueError(f"{path}: columns {', '.join(cols)} must be numbered {name}0..{name}{len(found) - 1} "
                         f"without gaps or repeats")
    return cols


SEPARATORS = {",": "comma", ";": "semicolon", "\t": "tab"}


def _dialect(raw: bytes) -> tuple[str, str]:
    """(separator, decimal mark) of a CSV file, from its header line: the commonest of comma, semicolon and
    tab there (the header's names hold none of them); a file separated by semicolons or tabs whose rows
    hold commas writes decimal commas ("1,5")."""
    text = raw.decode("utf-8", errors="replace")
    header = next((line for line in text.splitlines() if line.strip()), "")
    counts = {sep: header.count(sep) for sep in SEPARATORS}
    sep = max(counts, key=lambda k: (counts[k], k == ","))
    if not counts[sep]:
        sep = ","
    body = text[text.find(header) + len(header):]
    return sep, "," if sep != "," and "," in body else "."


def _lines(raw: bytes) -> np.ndarray:
    """The line number (1-based) of each data row, as pandas reads them (blank lines skipped, header first)."""
    text = raw.decode("utf-8", errors="replace")
    numbers = [i for i, line in enumerate(text.splitlines(), 1) if line.strip()]
    return np.asarray(numbers[1:], dtype=np.int64)


def _from_csv(path, raw: bytes):
    import pandas as pd

    sep, decimal = _dialect(raw)
    try:
        df = pd.read_csv(io.BytesIO(raw), sep=sep, decimal=decimal)
    except Exception as e:
        raise ValueError(f"{path}: cannot read as CSV separated by {SEPARATORS[sep]}s ({e})") from e
    header = [str(c).strip() for c in pd.read_csv(io.BytesIO(raw), sep=sep, header=None, nrows=1).iloc[0]]
    twice = sorted({c for c in header if header.count(c) > 1})
    if twice:   # pandas would rename the second one ("q1.1") and read the first alone
        raise ValueError(f"{path}: column{'s' if len(twice) > 1 else ''} {', '.join(twice)} named more than once; "
                         f"give each column one name")
    df.columns = [str(c).strip() for c in df.columns]
    out = {name: df[name].to_numpy() for name in COLUMNS if name in df.columns}
    for name in ARRAYS:
        cols = _columns(path, df, name)
        if cols:
            try:
                out[name] = df[cols].to_numpy(dtype=np.float64)
            except (TypeError, ValueError) as e:
                how = f" (read as separated by {SEPARATORS[sep]}s, decimal mark {decimal!r})" if sep != "," else ""
                raise ValueError(f"{path}: columns {', '.join(cols)} are not all numbers{how} ({e})") from e
    lines = _lines(raw)
    if lines.size == len(df):
        out[_LINES] = lines
    return out


def _from_npz(path, raw: bytes):
    try:
        with np.load(io.BytesIO(raw), allow_pickle=False) as z:
            out = {k: np.asarray(z[k], dtype=np.float64) for k in z.files if k in ARRAYS}
            return {**out, **{k: np.asarray(z[k]) for k in z.files if k in COLUMNS}}
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
        if k in COLUMNS:
            continue
        bad = int(np.sum(np.any(np.abs(v) > big, axis=1)))
        if bad:
            raise ValueError(f"{path}: {k} has {bad} rows with values beyond the {dtype} range (|x| > {big:.3g})")


def _first_bad(path: str, d: dict, cols: dict, lines) -> None:
    """A ValueError naming how many rows hold a NaN or infinite value, in which arrays, and the first of them:
    its line in a CSV file (its row in an .npz file) and its trajectory."""
    numeric = {**d, **{k: cols[k] for k in ("traj", "t") if k in cols}}
    masks = {}
    for k, v in numeric.items():
        try:
            finite = np.isfinite(np.asarray(v, dtype=np.float64))
        except (TypeError, ValueError):
            continue   # a column of text: refused as such further on
        masks[k] = ~(finite.reshape(len(finite), -1).all(axis=1))
    if not masks:
        return
    bad = np.any(np.stack(list(masks.values())), axis=0)
    if not bad.any():
        return
    i = int(np.argmax(bad))
    where = f"line {int(lines[i])}" if lines is not None else f"row {i} (counting from 0)"
    traj = cols.get("traj")
    if traj is not None:
        try:
            where += f", trajectory {float(traj[i]):g}"
        except (TypeError, ValueError):
            where += f", trajectory {traj[i]}"
    if "t" in cols and not masks.get("t", bad)[i]:
        where += f", t = {float(cols['t'][i]):g}"
    names = ", ".join(k for k, m in masks.items() if m.any())
    n = int(bad.sum())
    raise ValueError(f"{path}: {n} row{'s' if n > 1 else ''} with NaN or infinite values (in {names}), the first at "
                     f"{where}; remove or fill {'them' if n > 1 else 'it'}")


def _validate(p: Path, d: dict) -> dict:
    path = str(p)
    lines = d.pop(_LINES, None)
    cols = {k: d.pop(k) for k in COLUMNS if k in d}
    trajectories = "t" in cols and "split" not in cols
    missing = [k for k in (("q",) if trajectories else REQUIRED) if k not in d]
    what = "column" if p.suffix == ".csv" else "array"
    if missing and "q" in d and "t" not in cols and "split" not in cols:   # positions alone, without their times
        raise ValueError(f"{path}: no {what} t: positions q without {' and '.join(missing)} are a trajectory file, "
                         f"whose derivatives are estimated along its times; add the time {what} t (and traj where "
                         f"it holds several trajectories), or give {', '.join(missing)}")
    if missing:
        hint = "columns q0.., qdot0.., qddot0.." if p.suffix == ".csv" else "arrays q, qdot, qddot"
        if trajectories:
            hint = "a trajectory file: t, q" + ("0.." if p.suffix == ".csv" else "")
        raise ValueError(f"{path}: missing {', '.join(missing)} (expected {hint}, optional tau; or a trajectory "
                         f"file with t, q and optional traj, qdot, qddot, tau)")
    for k, v in d.items():
        if v.ndim == 1:
            d[k] = v = v[:, None]
        if v.ndim != 2:
            raise ValueError(f"{path}: {k} must be (N, d), got shape {v.shape}")
    shapes = {k: v.shape for k, v in d.items()}
    if len(set(shapes.values())) != 1:
        raise ValueError(f"{path}: mismatched shapes {shapes}; every array must be (N, d) with the same N and d")
    n = len(d["q"])
    for k, v in cols.items():
        if v.shape != (n,):
            raise ValueError(f"{path}: {k} must be one column of {n} values (as q), got shape {v.shape}")
    _first_bad(path, d, cols, lines)
    for k, v in cols.items():
        if k == "split":
            cols[k] = v.astype(str)
            continue
        try:
            cols[k] = v = v.astype(np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{path}: column {k} is not all numbers") from None
    if not cols and n < 20:
        raise ValueError(f"{path}: only {n} rows; need at least 20 (10 % are held out)")
    d.update(cols)
    return d


def rows(ref: str, kind: str) -> dict:
    """The raw arrays (q, qdot, qddot, tau and traj, t where the file has them) of the `kind` rows ("train",
    "heldout", "test") of the file `ref` names (a path, or `reference`'s text with or without "file:")."""
    d = load(*parse_reference(ref))
    if "split" in d:
        idx = np.flatnonzero(d["split"] == kind)
    else:
        n = len(d["q"])
        perm = np.random.default_rng(0).permutation(n)
        cut = max(1, n // 10)
        idx = perm[:cut] if kind == "heldout" else perm[cut:] if kind == "train" else perm[:0]
    return {k: v[idx] for k, v in d.items() if k != "split"}


def batch_of(r: dict, task: str) -> dict:
    """The model's inputs and target for `task` from rows of `rows`: a batch dict of `replication.training.data`."""
    q, qdot, qddot = r["q"], r["qdot"], r["qddot"]
    if task == "inverse_dynamics":
        return {"q": q, "qdot": qdot, "extra": qddot, "target": r["tau"], "qddot": qddot}
    if task == "hamiltonian":
        return {"q": q, "qdot": qdot, "target": np.concatenate([qdot, qddot], 1), "qddot": qddot}
    return {"q": q, "qdot": qdot, "target": qddot, "qddot": qddot}


def split_rows(ref: str, task: str, kind: str) -> dict:
    """The train or held-out rows of the file `ref` names, as a batch dict for `task`."""
    return batch_of(rows(ref, kind), task)
