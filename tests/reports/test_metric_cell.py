"""A claim's metric table cell: a seed whose energy error diverged is counted apart, never averaged in
(`reports.tables.metric_cell`, with the suite's one rule `replication.evaluation.diverged`)."""
from lagbench.reports.tables import metric_cell


def test_a_diverged_seed_is_counted_apart_not_averaged_in():
    assert metric_cell("energy_err_final_median", [0.004, 1.05e50]) == "0.004; 1 of 2 seeds diverged"
    assert metric_cell("test_energy_err_final", [float("inf"), 2e4]) == "2 of 2 seeds diverged"
    assert metric_cell("energy_err_final_median", [0.004, 0.006]).startswith("0.005 ± ")


def test_other_metrics_keep_large_values_and_shares_stay_shares():
    assert metric_cell("heldout_l1", [2e4, 4e4]) == "30000 ± 14000"
    assert metric_cell("heldout_l1", [None, None]) == "not recorded"
