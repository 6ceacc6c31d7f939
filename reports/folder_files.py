"""One file of a results folder read without raising: ``read_json`` gives a JSON object or None (the problem
collected), ``load_unit`` a unit folder ``units/<claim>/<framework>/<model>/seed<k>/`` as a :class:`Unit`
whose status is ``"ok"``, ``"failed"`` (the runner's own verdict) or ``"corrupt"`` (unreadable JSON, missing
keys, path mismatch, checksum or listed-file sha256 mismatch; see :mod:`reports.integrity`), with the reason.
``seed_key`` orders units by seed."""

from __future__ import annotations

import json
from pathlib import Path

from lagbench.reports.integrity import verify_unit
from lagbench.reports.loaded import Unit

UNIT_KEYS = ("claim", "framework", "model", "seed", "status", "metrics")


def read_json(path: Path, problems: list[str], root: Path) -> dict | None:
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, OSError) as exc:
        problems.append(f"{path.relative_to(root)} unreadable: {exc}")
        return None
    if not isinstance(data, dict):
        problems.append(f"{path.relative_to(root)} is not a JSON object")
        return None
    return data


def load_unit(root: Path, result_path: Path) -> Unit:
    unit_dir = result_path.parent
    rel = unit_dir.relative_to(root).as_posix()
    parts = unit_dir.relative_to(root / "units").parts
    claim, fw, model, seed = (list(parts) + ["?"] * 4)[:4]
    seed = seed.removeprefix("seed")
    try:
        result = json.loads(result_path.read_text(encoding="utf-8"))
        if not isinstance(result, dict):
            raise ValueError("not a JSON object")
    except (ValueError, OSError) as exc:
        return Unit(claim, fw, model, seed, unit_dir, rel, "corrupt", f"result.json unreadable: {exc}")
    reason = verify_unit(unit_dir, result)
    if reason is None:
        missing = [k for k in UNIT_KEYS if k not in result]
        if missing:
            reason = "missing keys: " + ", ".join(missing)
        elif (str(result["claim"]), str(result["framework"]), str(result["model"]), str(result["seed"])) \
                != (claim, fw, model, seed) or len(parts) != 4:
            reason = "folder does not match claim/framework/model/seed in result.json"
    if reason is not None:
        return Unit(claim, fw, model, seed, unit_dir, rel, "corrupt", reason, result)
    status = "ok" if result.get("status") == "ok" else "failed"
    failure = result.get("failure") or {}
    why = None if status == "ok" else str(failure.get("kind") or failure.get("message") or result.get("status"))
    return Unit(claim, fw, model, seed, unit_dir, rel, status, why, result)


def seed_key(seed: str) -> tuple[int, str]:
    return (int(seed), "") if seed.isdigit() else (1 << 30, seed)
