"""The speed study end to end in its tiny preset (seconds): every bench file exists with the documented
columns, throughputs are finite and positive, and the report's loader accepts the files. No timing is
asserted (speed figures are ratios within one run; see speedstudy)."""
import json

import numpy as np
import pandas as pd
import pytest

from lagbench.speedstudy.inference import TORCH_THREAD_CHOICES

COLUMNS = {
    "inference": ["system", "model", "formulation", "framework", "mode", "threads", "dtype", "batch", "samples_per_s",
                  "error"],
    "training": ["system", "model", "framework", "mode", "dtype", "batch", "steps_per_s", "samples_per_s"],
    "rollout": ["system", "solver", "rtol", "kind", "model", "source", "wall_s", "state_err", "energy_err"],
    "latency": ["model", "method", "framework", "dtype", "mode", "dispatch", "evals_per_s", "max_abs_diff"],
    "train_target": ["protocol", "budget", "threshold", "samples_to_reach", "reached", "extrapolated_samples",
                     "extrapolation"],
    "train_target_log": ["protocol", "samples", "heldout_l1"],
    "scaling": ["study", "formulation", "framework", "n", "seconds_per_eval", "samples_per_s"],
    "scaling_fit": ["study", "formulation", "framework", "exponent"],
    "ratios": ["operation", "kind", "dof", "jax", "torch", "ratio", "note"],
    "structure": ["system", "quadratic_kinetic", "separable", "local_coupling", "structured_model",
                  "general_model", "speedup"],
    "fast_paper": ["dof", "framework", "formulation", "samples_per_s", "flops_per_sample", "threads"],
    "matmul": ["dof", "framework", "gflops", "threads"],
    "members": ["framework", "members", "hidden", "batch", "steps", "wall_s", "step_s", "samples_per_s",
                "cost_vs_one", "step_cost_vs_one"],
}
POSITIVE = {"inference": ["samples_per_s"], "training": ["steps_per_s", "samples_per_s"],
            "rollout": ["wall_s"], "scaling": ["seconds_per_eval", "samples_per_s"], "latency": ["evals_per_s"],
            "fast_paper": ["samples_per_s"], "matmul": ["gflops"], "members": ["wall_s", "cost_vs_one"]}


@pytest.mark.parametrize("name", sorted(COLUMNS))
def test_csv_columns_and_throughputs(bench_dir, name):
    out, _ = bench_dir
    df = pd.read_csv(out / "bench" / f"{name}.csv")
    assert not df.empty
    assert [c for c in COLUMNS[name] if c not in df.columns] == []
    for col in POSITIVE.get(name, []):
        v = df[col].to_numpy(float)
        assert np.all(np.isfinite(v)) and np.all(v > 0), f"{name}.{col}: {v}"


def test_inference_covers_every_model_and_framework(bench_dir):
    out, _ = bench_dir
    df = pd.read_csv(out / "bench" / "inference.csv")
    got = set(zip(df["model"], df["formulation"], df["framework"], strict=True))
    for model, form in [("lnn", "paper"), ("lnn", "fast"), ("hnn", "-"), ("delan", "-"), ("baseline", "-"),
                        ("lgn", "dense"), ("lgn", "banded")]:
        assert {(model, form, "jax"), (model, form, "torch")} <= got
    assert {("truth", "sympy", fw) for fw in ("numpy", "jax", "torch")} <= got
    assert np.all(np.isfinite(df["error"].to_numpy(float)))
    truth = df[(df["model"] == "truth")]
    assert truth["error"].max() < 1e-4  # float32 ground truth against float64
    trained = df[df["source"] == "trained:dp_loss"]
    assert set(trained["framework"]) == {"jax"} and set(trained["hidden"].astype(str)) == {"8"}
    torch_rows = df[df["framework"] == "torch"]  # each with its JAX twin timed in the same rounds
    assert len(torch_rows) and (torch_rows["jax_paired_samples_per_s"] > 0).all()
    assert df.loc[df["framework"] != "torch", "jax_paired_samples_per_s"].isna().all()


def test_fast_paper_and_matmul_torch_rows_record_their_thread_count(bench_dir):
    out, _ = bench_dir
    for name in ("fast_paper", "matmul"):
        df = pd.read_csv(out / "bench" / f"{name}.csv")
        assert set(df.loc[df["framework"] == "jax", "threads"]) == {"default"}
        assert set(df.loc[df["framework"] == "torch", "threads"].astype(int)) <= set(TORCH_THREAD_CHOICES)


def test_rollout_has_chaos_floor_rk4_and_learned_models(bench_dir):
    out, _ = bench_dir
    df = pd.read_csv(out / "bench" / "rollout.csv")
    assert (df["kind"] == "chaos_floor").sum() == 1
    assert "rk4" in set(df["solver"])
    learned = df[df["kind"].str.startswith("learned")]
    assert set(zip(learned["model"], learned["kind"], strict=True)) == {("lnn", "learned"),
                                                                          ("baseline", "learned_tiny")}
    assert learned[learned["model"] == "lnn"]["source"].str.startswith("trained:fakekey").all()


def test_latency_compiled_matches_method_and_is_in_targets(bench_dir):
    out, targets = bench_dir
    df = pd.read_csv(out / "bench" / "latency.csv")
    assert {"method", "compile_single", "compile_single_frozen"} <= set(df[df["framework"] == "jax"]["mode"])
    assert set(df[df["framework"] == "jax"]["dispatch"]) == {"async", "sync"}
    assert "eager" in set(df[df["framework"] == "torch"]["mode"])
    assert df["max_abs_diff"].max() < 1e-4  # float32
    assert targets["delan_jax"]["best_mode"] and "met" in targets["delan_jax"]


def test_train_target_rows(bench_dir):
    out, targets = bench_dir
    df = pd.read_csv(out / "bench" / "train_target.csv")
    assert set(df["protocol"]) == {"original_scaled", "variant", "restarts", "restarts_fast", "restarts_halved",
                                 "baseline_reference"}
    assert set(df.loc[df["protocol"] == "baseline_reference", "model"]) == {"baseline"}
    lnn = df[df["model"] == "lnn"]
    assert np.all(np.isfinite(lnn["hessian_rel_err"].to_numpy(float)))
    assert np.all(np.isnan(df.loc[df["model"] == "baseline", "hessian_rel_err"].to_numpy(float)))
    assert "train_target_baseline_reference" not in targets  # a reference, not a target
    assert (df["skipped_steps"] >= 0).all()
    assert (df.loc[df["protocol"] == "original_scaled", "skipped_steps"] == 0).all()  # its guard is off
    assert df.loc[df["protocol"] == "variant", "description"].str.contains("gradient clip 100").all()
    assert set(df["threshold"]) == {10.0, 3.0, 1.0, 0.3, 0.073, 0.069}
    missed = df[~np.isfinite(df["samples_to_reach"].to_numpy(float))]
    assert missed["reached"].str.startswith("not reached within budget").all()
    assert np.isnan(missed["wall_s_to_reach"].to_numpy(float)).all()
    hit = df[np.isfinite(df["samples_to_reach"].to_numpy(float))]
    assert (hit["wall_s_to_reach"] <= hit["wall_s"]).all()
    assert df["extrapolation"].str.contains("EXTRAPOLATED").all()
    assert targets["train_target_variant"]["met"] in (True, False)
    assert set(targets["train_target_original_scaled"]["samples_to_reach"]) == {"10", "3", "1", "0.3", "0.073", "0.069"}


def test_ratio_notes_explain_every_ratio_beyond_2x(bench_dir):
    out, _ = bench_dir
    df = pd.read_csv(out / "bench" / "ratios.csv")
    r = df["ratio"].to_numpy(float)
    beyond = np.isfinite(r) & ((r > 2) | (r < 0.5))
    assert df[beyond]["note"].fillna("").str.len().min() > 20 if beyond.any() else True


def test_machine_and_targets(bench_dir):
    out, targets = bench_dir
    m = json.loads((out / "bench" / "machine.json").read_text())
    assert {"cpu", "cores", "gpu", "versions", "date"} <= set(m)
    assert "fast_over_paper_d2" in targets and "training_samples_per_s" in targets
    assert json.loads((out / "bench" / "targets.json").read_text())["preset"] == "tiny"


def test_report_loader_accepts_bench_files(bench_dir):
    from lagbench.reports.load import load_results

    out, _ = bench_dir
    res = load_results(out)
    assert {"inference", "training", "rollout", "scaling", "ratios", "latency", "train_target"} <= set(res.bench)
    assert not [p for p in res.problems if "bench/" in p]
    assert res.machine is not None


def test_report_speed_section_shows_latency_train_target_and_targets(bench_dir, tmp_path):
    from lagbench.reports.sections_speed import speed_sections

    out, _ = bench_dir
    titles = [b.title for s in speed_sections(load_results_of(out), tmp_path) for b in s.blocks if hasattr(b, "df")]
    assert any(t.startswith("Single-sample latency") for t in titles)
    assert any(t.startswith("Samples to reach held-out L1") for t in titles)
    assert any(t.startswith("Speed targets") for t in titles)
    tt = next(b.df for s in speed_sections(load_results_of(out), tmp_path) for b in s.blocks
              if hasattr(b, "df") and b.title.startswith("Samples to reach"))
    assert {"baseline_reference", "variant"} <= set(tt["protocol"]) and "hessian_rel_err" in tt.columns
    assert not (tt == "not run").any().any()  # NaN there means "not reached" or "no extrapolation": "-"


def load_results_of(out):
    from lagbench.reports.load import load_results

    return load_results(out)


def test_members_rows_pair_one_model_with_eight_and_with_one_at_eight_times_the_batch(bench_dir):
    out, _ = bench_dir
    df = pd.read_csv(out / "bench" / "members.csv")
    assert sorted(df["framework"].unique()) == ["jax", "torch"]
    assert dict(zip(df["framework"], df["mode"], strict=True)) == {"jax": "jit", "torch": "eager"}   # tiny: no compile
    for _, g in df.groupby("framework"):
        assert list(zip(g["members"], g["batch"], strict=True)) == [(1, 32), (8, 32), (1, 256)]
        assert float(g["cost_vs_one"].iloc[0]) == 1.0
        assert (g["samples_per_s"] > 0).all() and (g["cost_vs_one"].iloc[1:] > 0).all()
    targets = json.loads((out / "bench" / "targets.json").read_text())["targets"]
    assert targets["members_cost_vs_one"]["target"] == 2.5


def _members_row(fw, members, batch, cost, mode=None):
    return {"framework": fw, "members": members, "batch": batch, "cost_vs_one": cost,
            **({"mode": mode} if mode else {})}


def test_members_time_pytorch_eager_and_compiled_where_the_preset_compiles(monkeypatch):
    """Each PyTorch mode's rounds run under its LAGBENCH_TORCH_COMPILE setting, the row keeps the mode the
    steps really ran (a failed capture is eager), and each mode's cost is over its own one model."""
    import os
    from dataclasses import replace

    from lagbench.replication.training import compile_torch
    from lagbench.speedstudy import members
    from lagbench.speedstudy.timing import QUICK

    seen = []

    def fake_round(fw, spec, protocol, k, step):
        setting = os.environ.get(compile_torch.ENV)
        seen.append((fw, setting))
        ran = "jit" if fw == "jax" else ("compiled" if setting == "on" else "eager")
        if fw == "torch" and setting == "on" and protocol.batch > 32:
            ran = "eager (torch.compile failed: BackendCompilerFailed)"
        return {1: 1.0, 8: 2.0 if setting == "on" else 3.0}[k] * (2.0 if protocol.batch > 32 else 1.0), 0.5, ran

    monkeypatch.setattr(members, "_round", fake_round)
    sizes = replace(QUICK, members_steps=5, members_rounds=1)
    rows = members.members_rows(sizes)
    assert members.n_cases(sizes) == 3 and len(rows) == 9
    assert {s for fw, s in seen if fw == "torch"} == {"on", "off"}
    by = {(r["framework"], r["mode"], r["members"], r["batch"]): r["cost_vs_one"] for r in rows}
    assert by[("torch", "compiled", 8, 32)] == 2.0 and by[("torch", "eager", 8, 32)] == 3.0
    assert ("torch", "eager (torch.compile failed: BackendCompilerFailed)", 1, 256) in by
    from lagbench.speedstudy.targets import members_target
    t = members_target(rows)
    assert (t["jax"], t["torch"], t["torch_compiled"]) == (3.0, 3.0, 2.0) and t["met"] is False
    assert members.n_cases(replace(sizes, torch_compile=False)) == 2


def test_the_members_target_sets_the_members_beside_one_model_at_eight_times_the_batch():
    from lagbench.speedstudy.targets import members_target

    rows = [_members_row("jax", 1, 32, 1.0), _members_row("jax", 8, 32, 3.0), _members_row("jax", 1, 256, 2.4),
            _members_row("torch", 1, 32, 1.0), _members_row("torch", 8, 32, 2.4), _members_row("torch", 1, 256, 2.0)]
    t = members_target(rows)
    assert (t["jax"], t["torch"], t["jax_one_at_k_batch"], t["torch_one_at_k_batch"]) == (3.0, 2.4, 2.4, 2.0)
    assert t["met"] is False and t["floor_above_target"] is False   # both floors under 2.5: reachable
    rows[2] = _members_row("jax", 1, 256, 2.6)
    assert members_target(rows)["floor_above_target"] is True      # JAX's batching alone costs more than 2.5
    rows[1], rows[2] = _members_row("jax", 8, 32, 2.5), _members_row("jax", 1, 256, 2.4)
    rows[4] = _members_row("torch", 8, 32, 1.9)
    assert members_target(rows)["met"] is True
    assert "floor_above_target" not in members_target([r for r in rows if r["batch"] != 256])
    # a framework meets the bound in its best mode; its lowest floor decides whether the bound is in reach
    rows[4] = _members_row("torch", 8, 32, 2.9)
    rows += [_members_row("torch", 1, 32, 1.0, "compiled"), _members_row("torch", 8, 32, 2.2, "compiled"),
             _members_row("torch", 1, 256, 2.7, "compiled")]
    t = members_target(rows)
    assert (t["torch"], t["torch_compiled"], t["torch_compiled_one_at_k_batch"]) == (2.9, 2.2, 2.7)
    assert t["met"] is True and t["floor_above_target"] is False
