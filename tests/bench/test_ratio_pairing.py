"""replication.bench.tables on hand-made inference rows (no timing): the JAX/PyTorch ratio of an operation
pairs JAX with PyTorch's fastest row at that batch, whichever mode (eager, aoti) and thread count it
came from, and the note of a ratio beyond 2x names them; the DeLaN target reads the same fastest rows."""
import pytest

from replication.bench import tables


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
    t = tables.targets(list(rows.values()), [], [], ROWS, [])
    assert t["delan_torch"]["batched_acceleration"] == {"1": 8000.0, "256": 5e4}
    assert t["torch_within_1.5x_of_jax_inference"]["n_beyond"] == 1
