"""The report reads `lagbench train-target --out ROOT` results (ROOT/train_target/): a table and the curve."""
import pandas as pd

from lagbench.reports.load import load_results
from lagbench.reports.sections_speed import speed_sections

THRESHOLDS = (10.0, 3.0, 1.0, 0.3, 0.073)


def _write(root, rows=True, log=True):
    folder = root / "train_target"
    folder.mkdir(parents=True)
    if rows:
        pd.DataFrame([{"protocol": p, "model": "lnn", "description": "d", "seed": seed, "hidden": "8x8",
                       "budget": 3e7, "threshold": t, "samples_to_reach": reach if t >= 0.073 else float("nan"),
                       "reached": "yes", "best_l1": best, "final_l1": best, "hessian_rel_err": 0.01,
                       "skipped_steps": 3, "samples_per_s": 1e4, "extrapolated_samples": float("nan"),
                       "extrapolation": "EXTRAPOLATED, not measured"}
                      for p, seed, reach, best in (("restarts", 4, 2.74e7, 0.044), ("variant", 0, float("nan"), 4.9))
                      for t in THRESHOLDS]).to_csv(folder / "train_target.csv", index=False)
    if log:
        pd.DataFrame([{"protocol": p, "samples": s, "heldout_l1": v} for p in ("restarts", "variant")
                      for s, v in ((0, 60.0), (1e6, 5.0), (3e7, 0.044 if p == "restarts" else 4.9))]
                     ).to_csv(folder / "train_target_log.csv", index=False)


def _blocks(root, out):
    return [b for s in speed_sections(load_results(root), out) for b in s.blocks]


def test_table_and_curve(tmp_path):
    _write(tmp_path / "res")
    blocks = _blocks(tmp_path / "res", tmp_path / "rep")
    table = next(b for b in blocks if getattr(b, "title", "").startswith("Train to target (lagbench train-target)"))
    assert set(table.df["protocol"]) == {"restarts", "variant"} and set(table.df["seed"]) == {"4", "0"}
    assert (table.df.loc[table.df["protocol"] == "variant", "samples_to_reach"] == "-").all()
    assert (tmp_path / "rep" / "figures" / "train_target_train_target.png").stat().st_size > 0
    assert any(getattr(b, "sources", None) == ["train_target/train_target_log.csv"] for b in blocks)


def test_missing_columns_are_named_and_the_file_unused(tmp_path):
    _write(tmp_path / "res", log=False)
    pd.DataFrame({"protocol": ["x"]}).to_csv(tmp_path / "res" / "train_target" / "train_target_log.csv")
    res = load_results(tmp_path / "res")
    assert "train_target" in res.train_target and "train_target_log" not in res.train_target
    assert any("train_target/train_target_log.csv lacks columns" in p for p in res.problems)


def test_nothing_without_the_folder(tmp_path):
    (tmp_path / "res").mkdir()
    assert not any(getattr(b, "title", "").startswith("Train to target") for b in _blocks(tmp_path / "res", tmp_path))


def test_the_distribution_over_runs_counts_every_run_and_takes_the_median_over_those_that_reached(tmp_path):
    folder = tmp_path / "res" / "train_target"
    folder.mkdir(parents=True)
    pd.DataFrame([{"protocol": "restarts_halved", "run": r, "init_seed": 1000 + 16 * r, "chosen_seed": 1000 + 16 * r,
                   "split": "test", "threshold": 0.069, "reached": wall is not None,
                   "samples_to_reach": 3.6e7 if wall else float("nan"), "wall_s_to_reach": wall or float("nan"),
                   "best_l1": 0.06, "final_l1": 0.06 if wall else 0.2, "hessian_rel_err": 0.01, "samples_per_s": 4e4,
                   "budget": 4e7} for r, wall in enumerate((800.0, None, 900.0, 1000.0))]).to_csv(
        folder / "distribution.csv", index=False)
    blocks = _blocks(tmp_path / "res", tmp_path / "rep")
    summary = next(b for b in blocks if getattr(b, "title", "").startswith("Time to the paper's held-out L1 0.069"))
    row = summary.df.iloc[0]
    assert row["reached"] == "3 of 4" and float(row["wall_s_to_reach_median"]) == 900.0
    assert float(row["wall_s_to_reach_min"]) == 800.0 and float(row["wall_s_to_reach_max"]) == 1000.0
    every = next(b for b in blocks if getattr(b, "title", "") == "Time to held-out L1 0.069, every run")
    assert len(every.df) == 4
