"""Earlier forms of a protocol's `to_dict`, read into the current one (`Protocol.from_dict`), so that result
folders written under them still load. A cache key is never migrated: each form hashes to its own keys.

- version 1 (flat): the optional parts as flat fields, 0 = off or "the protocol's value"; fields at 0 left
  out; `eval` and `rollback` present.
- version 2: the optional parts as records (`scouting` with its own `lr` and `lr_start`), data, optimiser
  and schedule as flat fields.
- version 3 (current): data, optimiser and schedule as records as well; a scouting holds its schedule.
"""
from __future__ import annotations

V1_SCOUT_SAMPLES = 500_000   # a version-1 protocol's samples per scout when it gave no scout_steps
# the flat fields' defaults in versions 1 and 2 (a version-1 dict leaves some out)
FLAT_DEFAULTS = {"n_heldout": 10_000, "system_params": (), "resample": False, "coords": "qqdot", "lr": 1e-3,
                 "schedule": "onecycle", "lr_start": 0.2, "lr_min_ratio": 1e-4, "lr_step_every": 1000,
                 "lr_step_gamma": 0.1, "b1": 0.9, "b2": 0.999, "eps": 1e-8}


def upgraded(d: dict, current: int) -> dict:
    """A protocol dict of any known version in the form of version `current`."""
    version = d.get("version", 1)
    if version not in (1, 2, current):
        raise ValueError(f"protocol version {version!r} is not known; this suite reads 1 to {current}")
    if version == 1:
        d = from_v1(d)
    if d.get("version", 1) == 2:
        d = from_v2(d)
    return d


def from_v1(d: dict) -> dict:
    """A version-1 (flat) dict in the form of version 2."""
    d = {**FLAT_DEFAULTS, **d}
    d.pop("version", None)
    d.pop("eval", None)
    if d.pop("rollback", 0):
        raise ValueError("a protocol with rollback (version 1) cannot be read: rollback is no longer a protocol part")
    clip, skip = d.pop("grad_clip", 0), d.pop("spike_skip", 0)
    d["guard"] = {"clip": clip or None, "skip": skip or None} if (clip or skip) else None
    flat = {k: d.pop(f"scout{k}", 0) for k in ("s", "_steps", "_batch", "_lr", "_lr_start", "_keep")}
    d["scouting"] = None
    if flat["s"] > 1:
        batch = flat["_batch"] or d["batch"]
        d["scouting"] = {"count": flat["s"], "steps": flat["_steps"] or max(V1_SCOUT_SAMPLES // batch, 1), "batch": batch,
                         "lr": flat["_lr"] or d["lr"], "lr_start": flat["_lr_start"] or d["lr_start"],
                         "keep": flat["_keep"] or None}
    cohort = d.pop("cohort", 0)
    d["cohort"] = cohort if cohort and cohort > 1 else None
    every = d.pop("track_every", 0)
    d["tracking"] = {"every": every} if every else None
    return {"version": 2, **d}


def _schedule(kind: str, lr: float, d: dict) -> dict:
    if kind == "constant":
        return {"kind": kind, "lr": lr}
    if kind == "step":
        return {"kind": kind, "lr": lr, "every": d["lr_step_every"], "gamma": d["lr_step_gamma"]}
    return {"kind": kind, "lr": lr, "start": d["lr_start"], "min_ratio": d["lr_min_ratio"]}


def from_v2(d: dict) -> dict:
    """A version-2 dict in the form of version 3: the scouts' schedule is the protocol's shape with the
    scouting's peak (and, for a one-cycle, its start)."""
    d = {**FLAT_DEFAULTS, **d}
    d.pop("version", None)
    kind = d.pop("schedule")
    flat = {k: d.pop(k) for k in ("lr", "lr_start", "lr_min_ratio", "lr_step_every", "lr_step_gamma")}
    out = {k: v for k, v in d.items() if k not in ("data", "n_train", "n_heldout", "resample", "system_params",
                                                   "coords", "b1", "b2", "eps")}
    out["data"] = {"recipe": d["data"], "n_train": d["n_train"], "n_heldout": d["n_heldout"], "resample": d["resample"],
                   "system_params": d["system_params"], "coords": d["coords"]}
    out["optimiser"] = {"b1": d["b1"], "b2": d["b2"], "eps": d["eps"]}
    out["schedule"] = _schedule(kind, flat["lr"], flat)
    s = d.get("scouting")
    if s is not None:
        s = dict(s)
        lr, start = s.pop("lr"), s.pop("lr_start")
        s["schedule"] = _schedule(kind, lr, {**flat, "lr_start": start})
        out["scouting"] = s
    return {"version": 3, **out}
