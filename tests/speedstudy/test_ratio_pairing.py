"""speedstudy.tables on hand-made inference rows (no timing): the JAX/PyTorch ratio of an operation
pairs JAX with PyTorch's fastest row at that batch, whichever mode (eager, aoti) and thread count it
came from, and the note of a ratio beyond 2x names them; the DeLaN target reads the same fastest rows;
rows timed in the same interleaved rounds as their JAX twin are compared within those rounds."""
import pytest

from lagbench.speedstudy import tables, targets


def _row(fw, mode, threads, batch, rate, model="delan"):
    return {"system": "double_pendulum", "model": model, "formulation": "-", "framework": fw, "mode": mode,
            "threads": threads, "dtype": "float32", "batch": batch, "samples_per_s": rate, "error": 0.1,
            "source": "random_init", "ops": 10 if mode != "aoti" else None}


ROWS = [_row("jax", "jit", "default", 1, 4000.0), _row("jax", "jit", "default", 256, 2e5),
        _row("torch", "eager", 1, 1, 500.0), _row("torch", "eager", 2, 256, 5e4),
        _row("torch", "aoti", 2, 1, 8000.0), _row("torch", "aoti", 1, 256, 1e4)]


def test_fastest_per_batch_keeps_one_row_per_batch():
    best = tables.fastest_per_batch(ROWS)
    got = {(r["framework"], r["batch"]): (r["mode"], r["threads"]) for r in best}
    assert got == {("jax", 1): ("jit", "default"), ("jax", 256): ("jit", "default"),
                   ("torch", 1): ("aoti", 2), ("torch", 256): ("eager", 2)}


def test_ratio_uses_the_fastest_torch_row_and_names_it():
    rows = {r["operation"]: r for r in tables.ratio_rows(ROWS, [], [], [], [], [])}
    one, big = rows["q'' double_pendulum delan/- float32 batch 1"], rows["q'' double_pendulum delan/- float32 batch 256"]
    assert one["ratio"] == pytest.approx(0.5) and one["note"] == ""  # within 2x: no note
    assert big["ratio"] == pytest.approx(4.0)
    assert "PyTorch 2 (eager" in big["note"]
    t = targets.targets(list(rows.values()), [], [], ROWS, [])
    assert t["delan_torch"]["batched_acceleration"] == {"1": 8000.0, "256": 5e4}
    assert t["torch_within_1.5x_of_jax_inference"]["n_beyond"] == 1


def _fp(fw, form, mode, rate, dof=2, threads=1):
    return {"dof": dof, "framework": fw, "formulation": form, "mode": mode, "batch": 4096, "seconds": 4096 / rate,
            "samples_per_s": rate, "flops_per_sample": 1e6 if fw == "jax" else float("nan"), "gflops": 1.0,
            "threads": threads}


FP = [_fp("jax", "paper", "jit", 8000.0), _fp("jax", "fast", "jit", 16000.0),
      _fp("torch", "paper", "eager", 2000.0), _fp("torch", "paper", "traced", 5000.0, threads=2),
      _fp("torch", "fast", "eager", 9000.0), _fp("torch", "fast", "aoti", 7000.0)]


def test_fast_paper_rows_take_each_formulations_fastest_mode():
    """The 3 x 600 rows: PyTorch's paper LNN at its traced rate, its fast LNN at its eager one; the fast/paper
    speedup divides those two; the note of a ratio beyond 2x names the compiled mode."""
    best = {(r["framework"], r["formulation"]): r["mode"] for r in tables.fastest_mode(FP)}
    assert best == {("jax", "paper"): "jit", ("jax", "fast"): "jit", ("torch", "paper"): "traced",
                    ("torch", "fast"): "eager"}
    matmul = [{"dof": 2, "framework": fw, "rows": 3, "seconds": 1.0, "gflops": 20.0, "threads": 1} for fw in ("jax", "torch")]
    rows = {r["operation"]: r for r in tables.ratio_rows([], [], [], FP, matmul, [])}
    assert rows["q'' lnn/paper d=2 float32 batch 4096 (3x600 target)"]["ratio"] == pytest.approx(1.6)
    assert rows["q'' lnn/fast d=2 float32 batch 4096 (3x600 target)"]["ratio"] == pytest.approx(16 / 9)
    sp = rows["fast/paper speedup d=2"]
    assert sp["jax"] == pytest.approx(2.0) and sp["torch"] == pytest.approx(9000 / 5000)
    slow = tables.ratio_rows([], [], [], [_fp("jax", "paper", "jit", 8000.0), _fp("torch", "paper", "traced", 2000.0)],
                             [], [])
    assert "PyTorch traced" in slow[0]["note"] and "eager" not in slow[0]["note"]


def test_paired_rows_compare_within_their_own_rounds():
    """Rows that carry the JAX rate of their own interleaved rounds: the ratio is the best of those
    within-round ratios (here the eager row, 1.25, although the aoti row is faster against a slower JAX
    round), the JAX column is that round's rate, and rows without it keep the separate comparison."""
    paired = [dict(r) for r in ROWS]
    paired[4]["jax_paired_samples_per_s"] = 12000.0          # aoti batch 1: 8000 against 12000 -> 1.5
    paired[2]["jax_paired_samples_per_s"] = float("nan")    # eager batch 1: no pairing (an older file)
    paired[3]["jax_paired_samples_per_s"] = 6.25e4          # eager batch 256: 5e4 against 6.25e4 -> 1.25
    paired[5]["jax_paired_samples_per_s"] = 4e4             # aoti batch 256: 1e4 against 4e4 -> 4.0
    best = tables.paired_best(paired)
    assert {k[-1]: (r["mode"], r["batch"]) for k, r in best.items()} == {1: ("aoti", 1), 256: ("eager", 256)}
    rows = {r["operation"]: r for r in tables.ratio_rows(paired, [], [], [], [], [])}
    one, big = rows["q'' double_pendulum delan/- float32 batch 1"], rows["q'' double_pendulum delan/- float32 batch 256"]
    assert (one["jax"], one["torch"], one["ratio"]) == (12000.0, 8000.0, pytest.approx(1.5))
    assert (big["jax"], big["torch"], big["ratio"]) == (6.25e4, 5e4, pytest.approx(1.25))
    t = targets.targets(list(rows.values()), [], [], paired, [])
    assert t["torch_within_1.5x_of_jax_inference"] == {"worst_jax_over_torch": pytest.approx(1.5), "n_ops": 2,
                                                       "n_beyond": 0, "met": True}


def test_targets_read_rows_by_their_fields_not_their_display_names():
    """Renaming every row's `operation` changes no target: the targets select by kind and dof."""
    matmul = [{"dof": 2, "framework": fw, "rows": 3, "seconds": 1.0, "gflops": 20.0, "threads": 1} for fw in ("jax", "torch")]
    rows = tables.ratio_rows(ROWS, [], [], FP, matmul, ["a note"])
    assert {r["kind"] for r in rows} <= set(tables.KINDS)
    t = targets.targets(rows, [], [], ROWS, [])
    assert "fast_over_paper_d2" in t and "fast_LNN_fraction_of_roofline_d=2" in t
    assert t["torch_within_1.5x_of_jax_inference"]["n_ops"] == 4   # two batched rows, two 3 x 600 rows
    renamed = [{**r, "operation": f"row {i}"} for i, r in enumerate(rows)]
    assert targets.targets(renamed, [], [], ROWS, []) == t
