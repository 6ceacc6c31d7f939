"""`replication.run.same_numbers`: two runs' units.csv compared column by column, timings apart."""
import pandas as pd

from lagbench.replication.run.same_numbers import compare, main

ROWS = pd.DataFrame({"claim": ["a", "a"], "framework": ["jax", "torch"], "model": ["lnn", "lnn"], "seed": [1000, 1000],
                     "heldout_l1": [0.1, float("nan")], "status": ["ok", "failed"], "wall_time_s": [3.0, 4.0]})


def test_the_same_numbers_in_another_order_and_other_timings_are_the_same(tmp_path):
    other = ROWS.iloc[::-1].assign(wall_time_s=[9.0, 8.0])
    r = compare(ROWS, other)
    assert r["differ"] == [] and r["timing_differ"] == ["wall_time_s"] and r["rows"] == 2
    ROWS.to_csv(tmp_path / "a.csv", index=False)
    other.to_csv(tmp_path / "b.csv", index=False)
    assert main([str(tmp_path / "a.csv"), str(tmp_path / "b.csv")]) == 0


def test_a_changed_number_a_missing_row_or_column_is_found(tmp_path):
    assert compare(ROWS, ROWS.assign(heldout_l1=[0.1 + 1e-12, float("nan")]))["differ"] == ["heldout_l1"]
    assert compare(ROWS, ROWS.iloc[:1])["unmatched"] == [("a", "torch", "lnn", "1000")]
    ROWS.to_csv(tmp_path / "a.csv", index=False)
    ROWS.drop(columns="status").to_csv(tmp_path / "b.csv", index=False)
    assert main([str(tmp_path / "a.csv"), str(tmp_path / "b.csv")]) == 1
    assert main([str(tmp_path / "a.csv"), str(tmp_path / "missing.csv")]) == 2
