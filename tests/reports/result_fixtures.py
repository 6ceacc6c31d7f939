"""Hand-made result files following docs/RESULTS.md exactly, checksums included (used by the
conftest.py fixtures and the tests).

``write_results(root)`` writes run.json, claims.json (the ten claims; ``init_study`` a pooled claim whose
metric is a yes/no per seed), units for every claim except ``activation_study`` (which stays "not run") in jax
and torch with two seeds, summary/units.csv,
summary/verdicts.json and bench/ files; plus one corrupt unit (``dp_loss/torch/lnn/seed2``: its metrics
were edited after the checksum was written). Checksums are computed here independently of ``reports``.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pandas as pd

from lagbench.replication.training.protocol import Data, Protocol

FRAMEWORKS = ["jax", "torch"]
PROTOCOL = Protocol(data=Data("double_pendulum_iid", n_train=10000), steps=100, batch=32).to_dict()
SEEDS = [0, 1]
POOLED = "init_study"   # a claim whose metric is a yes/no per seed (left_plateau: 1 on seed 0, 0 on seed 1)
CORRUPT = ("dp_loss", "torch", "lnn", 2)
NOT_RUN_CLAIM = "activation_study"

CLAIMS = [
    # id, number, paper, section, system, models, metric, published
    ("dp_loss", 1, "LNN", "§5", "double_pendulum", ["lnn", "baseline"], "heldout_l1",
     {"lnn": 0.073, "baseline": 0.074}),
    ("dp_energy", 2, "LNN", "§5 / Fig. 2(b)", "double_pendulum", ["lnn", "baseline"], "energy_err_final",
     {"lnn": 0.0043, "baseline": 0.0736}),
    ("rel_coords", 3, "LNN", "§5 / Fig. 5", "relativistic", ["hnn_qqdot", "hnn_qp", "lnn"], "heldout_l1",
     {"hnn_qqdot": 0.41, "hnn_qp": 2.4e-4, "lnn": 7.9e-4}),
    ("wave_lgn", 4, "LNN", "§5 / Fig. 6", "wave", ["lgn"], "heldout_l1", {"lgn": None}),
    ("appendix_b", 5, "LNN", "App. B", "free_fall", ["lnn_exact"], "max_abs_err", {"lnn_exact": 0.0}),
    ("init_study", 6, "LNN", "App. C", "double_pendulum",
     ["lnn_init-cranmer2020", "lnn_init-xavier", "lnn_init-kaiming", "lnn_init-pytorch_default"],
     "left_plateau", {}),
    ("activation_study", 7, "LNN", "App. C", "double_pendulum",
     ["lnn_act-softplus", "lnn_act-relu2", "lnn_act-tanh"], "final_train_loss", {}),
    ("delan_table1", 8, "LNN", "Table 1", ["relativistic", "charged_magnetic"], ["delan", "lnn"], "heldout_l1",
     {"delan": None, "lnn": None}),
    ("delan_arm", 9, "DeLaN", "§5", "two_link_arm", ["delan", "ff", "delan_n100", "ff_n100", "delan_n1000",
                                                     "ff_n1000"], "torque_mse_test",
     {"delan": 4.3e-4, "ff": 1.3e-2}),
    ("hnn_energy", 10, "HNN", "§3", ["spring", "pendulum"], ["hnn", "baseline"], "energy_err_max",
     {"hnn": None, "baseline": None}),
]


def sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def checksum(result: dict) -> str:
    body = {k: v for k, v in result.items() if k != "checksum"}
    return sha(json.dumps(body, sort_keys=True, separators=(",", ":")).encode("utf-8"))


def write_json(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=1), encoding="utf-8")


def claim_record(c) -> dict:
    cid, number, paper, section, system, models, metric, published = c
    return {"id": cid, "number": number, "paper": paper, "section": section, "title": f"claim {cid}",
            "system": system, "models": models, "metric": metric, "metric_label": metric,
            "published": published, "verdict_rule": "first model < second model", "pooled": cid == POOLED,
            "protocol": {"smoke": {"steps": 10}, "quick": {"steps": 100}, "paper": {"steps": 1000}}}


def metrics_for(cid, model, seed, rng) -> dict:
    size = int(model.rsplit("_n", 1)[1]) if "_n" in model and model.rsplit("_n", 1)[1].isdigit() else 10000
    base = {"lnn": 0.07, "baseline": 0.08, "hnn_qqdot": 0.4, "hnn_qp": 3e-4, "lgn": 0.02, "lnn_exact": 1e-15,
            "delan": 5e-4, "ff": 1e-2, "hnn": 0.01}.get(model.split("_n")[0], 0.05 * (1 + len(model) % 4))
    base *= (10000 / size) ** 0.5
    m = {k: base * s * (1 + 0.01 * rng.standard_normal()) for k, s in
         (("heldout_l1", 1), ("heldout_mse", 0.5), ("energy_err_final", 0.1), ("energy_err_max", 0.3),
          ("final_train_loss", 0.9), ("max_abs_err", 1), ("torque_mse_train", 0.5), ("torque_mse_test", 1),
          ("transfer_l1", 2))}
    m["null_heldout_l1"] = 50.0   # the null predictor's: every fixture model is far below it
    if cid == POOLED:
        m["left_plateau"] = float(seed == 0)
    return m


def arrays_for(cid, rng) -> dict[str, np.ndarray]:
    t = np.linspace(0.0, 10.0, 50)
    if cid == "dp_energy":
        q = np.stack([np.sin(t), np.cos(1.3 * t)], -1)
        return {"t": t, "q_true": q, "q_pred": q + 0.01 * rng.standard_normal(q.shape)}
    if cid == "wave_lgn":
        x = np.linspace(0.0, 1.0, 20)
        f = np.exp(-((x[None, :] - 0.5 - 0.03 * t[:, None]) % 1.0 - 0.0) ** 2 / 0.01)
        return {"x": x, "t": t, "field_true": f, "field_pred": f + 0.01 * rng.standard_normal(f.shape)}
    if cid == "rel_coords":
        v = np.tanh(np.linspace(0.2, 0.9, 3)[:, None] + 0.5 * t[None, :])[..., None]
        return {"t": t, "q_true": np.cumsum(v, 1) * 0.2, "q_pred": np.cumsum(v, 1) * 0.2, "qdot_true": v,
                "qdot_pred": v + 0.01 * rng.standard_normal(v.shape)}
    if cid == "delan_arm":
        m = rng.standard_normal((30, 2, 2))
        c, g = rng.standard_normal((30, 2)), rng.standard_normal((30, 2))
        tau = np.stack([np.sin(t[:30]), np.cos(t[:30])], -1)
        return {"M_true": m, "M_pred": m + 0.05 * rng.standard_normal(m.shape), "c_true": c,
                "c_pred": c * 1.02, "g_true": g, "g_pred": g * 0.98, "tau_true": tau, "tau_pred": tau * 1.01}
    return {}


def write_unit(root: Path, cid: str, fw: str, model: str, seed: int, rng) -> dict:
    udir = root / "units" / cid / fw / model / f"seed{seed}"
    udir.mkdir(parents=True, exist_ok=True)
    steps = np.arange(0, 100, 10)
    pd.DataFrame({"step": steps, "loss": np.exp(-steps / 40) + 0.01 * rng.random(len(steps)),
                  "grad_norm": 1.0, "lr": 1e-3, "wall_s": steps * 0.01}).to_csv(udir / "train_log.csv", index=False)
    files = ["train_log.csv"]
    if cid in ("dp_energy", "hnn_energy", "wave_lgn"):
        t = np.linspace(0, 10, 20)
        rows = [(traj, ti, "energy_err", 1e-4 * (1 + traj) * (1 + ti) * (3 if "baseline" in model else 1))
                for traj in range(2) for ti in t]
        if cid == "wave_lgn":   # the pulse's total energy, truth and model
            rows = [(0, ti, q, 0.45 * (1 + (1e-3 * ti * rng.random() if q == "energy_pred" else 0)))
                    for ti in t for q in ("energy_true", "energy_pred")]
        pd.DataFrame(rows, columns=["traj", "t", "quantity", "value"]).to_csv(udir / "timeseries.csv", index=False)
        pd.DataFrame({"traj": [0, 1], "energy_err_final": [1e-3, 2e-3], "state_err_gm": [0.1, 0.2]}).to_csv(
            udir / "rollouts.csv", index=False)
        files += ["timeseries.csv", "rollouts.csv"]
    arrays = arrays_for(cid, rng)
    if arrays:
        np.savez(udir / "arrays.npz", **arrays)
        files.append("arrays.npz")
    metrics = metrics_for(cid, model, seed, rng)
    result = {
        "schema": 1, "claim": cid, "framework": fw, "model": model, "seed": seed, "profile": "smoke",
        "status": "ok", "failure": None, "metrics": metrics, "counters": {"hessian_fallbacks": 0},
        "model_spec": {"kind": model.split("_")[0], "dof": 2, "hidden": [16, 16], "activation": "softplus",
                       "init": "cranmer2020"},
        "protocol": PROTOCOL, "dtype": "float32",
        "wall_time_s": 2.0, "train_time_s": 1.5 + seed, "train_steps": 100,
        "train_samples_per_s": (1000.0 if fw == "jax" else 800.0) * (2 if "baseline" in model else 1),
        "versions": {"python": "3.11.7", "numpy": "2.4", fw: "1.0"}, "commit": "abc1234",
        "hardware": {"cpu": "test cpu", "cores": 2, "gpu": None}, "created": "2026-11-21T10:00:00Z",
        "arrays": {"arrays.npz": sorted(arrays)} if arrays else {},
        "files": {f: sha((udir / f).read_bytes()) for f in files},
    }
    result["checksum"] = checksum(result)
    write_json(udir / "result.json", result)
    return result


def write_bench(root: Path) -> None:
    b = root / "bench"
    b.mkdir(parents=True, exist_ok=True)
    write_json(b / "machine.json", {"cpu": "test cpu", "cores": 2, "gpu": None, "versions": {"jax": "1", "torch": "2"}})
    rows = [(s, m, f, fw, "float32", 256, thr, err) for s in ("double_pendulum", "relativistic")
            for m, f, thr, err in (("lnn", "paper", 1e3, 0.07), ("lnn", "fast", 1e4, 0.07), ("baseline", "mlp", 1e5, 0.2))
            for fw in FRAMEWORKS]
    pd.DataFrame(rows, columns=["system", "model", "formulation", "framework", "dtype", "batch", "samples_per_s",
                                "error"]).to_csv(b / "inference.csv", index=False)
    pd.DataFrame([("double_pendulum", "lnn", fw, "fast", "float32", 512, 10.0, 5120.0) for fw in FRAMEWORKS],
                 columns=["system", "model", "framework", "mode", "dtype", "batch", "steps_per_s",
                          "samples_per_s"]).to_csv(b / "training.csv", index=False)
    pd.DataFrame([("chain", form, fw, n, 1e-5 * n ** (3 if form == "dense" else 1), 1e5 / n)
                  for form in ("dense", "banded") for fw in FRAMEWORKS for n in (2, 8, 32)],
                 columns=["study", "formulation", "framework", "n", "seconds_per_eval", "samples_per_s"]).to_csv(
        b / "scaling.csv", index=False)
    pd.DataFrame([("lnn_fast_qddot", 1.0e-4, 1.5e-4, 1.5, "cpu")],
                 columns=["operation", "jax", "torch", "ratio", "note"]).to_csv(b / "ratios.csv", index=False)


def write_results(root: Path, only=None) -> Path:
    """Every claim of `CLAIMS`, or the ids in `only` (the corrupt unit's claim among them)."""
    assert only is None or CORRUPT[0] in only, f"the corrupt unit belongs to {CORRUPT[0]}"
    rng = np.random.default_rng(0)
    claims = [claim_record(c) for c in CLAIMS if only is None or c[0] in only]
    write_json(root / "run.json", {"profile": "smoke", "frameworks": FRAMEWORKS, "seeds": SEEDS,
                                   "versions": {"python": "3.11.7"}, "hardware": {"cpu": "test cpu", "cores": 2},
                                   "commit": "abc1234", "started": "2026-11-21T09:00:00Z",
                                   "finished": "2026-11-21T10:00:00Z"})
    write_json(root / "claims.json", {"schema": 1, "claims": claims})
    units, verdicts = [], []
    for c in claims:
        if c["id"] == NOT_RUN_CLAIM:
            verdicts.append({"id": c["id"], "verdict": "not run", "by_framework": {}, "reason": "", "values": {}})
            continue
        for fw in FRAMEWORKS:
            for model in c["models"]:
                for seed in SEEDS:
                    r = write_unit(root, c["id"], fw, model, seed, rng)
                    units.append({"claim": c["id"], "framework": fw, "model": model, "seed": seed,
                                  "status": "ok", **r["metrics"]})
        verdicts.append({"id": c["id"], "verdict": "reproduced", "by_framework": {fw: "reproduced" for fw in FRAMEWORKS},
                         "reason": "fixture", "values": {}})
    bad = write_unit(root, *CORRUPT, rng)
    bad["metrics"]["heldout_l1"] = 999.0  # edited after the checksum: must be flagged and excluded
    write_json(root / "units" / CORRUPT[0] / CORRUPT[1] / CORRUPT[2] / f"seed{CORRUPT[3]}" / "result.json", bad)
    (root / "summary").mkdir(parents=True, exist_ok=True)
    pd.DataFrame(units).to_csv(root / "summary" / "units.csv", index=False)
    write_json(root / "summary" / "verdicts.json", {"schema": 1, "profile": "smoke", "claims": verdicts})
    write_bench(root)
    return root
