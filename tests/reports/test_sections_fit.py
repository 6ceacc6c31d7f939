"""The fit section's models table counts a `--test` file's rows (recorded apart from the fit's split)."""
from types import SimpleNamespace

from lagbench.reports.sections_fit import _models_table


def test_the_rows_column_counts_the_test_file():
    cfg = {"rows": {"train": 80, "heldout": 20}, "test_rows": 35}
    u = SimpleNamespace(claim="fit", model="lnn", framework="jax", seed=0,
                        result={"protocol": {"task": "acceleration"}, "model_spec": {"hidden": [8]},
                                "eval_config": cfg, "train_steps": 10})
    assert _models_table([u])["rows (train/held-out/test)"].tolist() == ["80/20/35"]
    u.result["eval_config"] = {"rows": {"train": 80, "heldout": 20}}
    assert _models_table([u])["rows (train/held-out/test)"].tolist() == ["80/20/0"]
