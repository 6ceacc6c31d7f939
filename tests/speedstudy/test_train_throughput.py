"""The training-throughput measurement runs a claim's model through the one training loop in both
frameworks on the device asked for, and says where and how fast it trained."""
import math

from lagbench.speedstudy.train_throughput import main, measure


def test_throughput_rows_per_framework_on_the_cpu(tmp_path):
    df = measure("dp_loss", "lnn", "smoke", ("jax", "torch"), "cpu", steps=4)
    assert list(df["framework"]) == ["jax", "torch"] and set(df["device"]) == {"cpu"}
    assert (df["steps"] == 4).all() and df["samples_per_s"].map(math.isfinite).all()
    assert df["failure"].isna().all()
    assert main(["--profile", "smoke", "--steps", "2", "--frameworks", "jax", "--device", "cpu",
                 "--out", str(tmp_path / "t.csv")]) == 0
    assert (tmp_path / "t.csv").exists()
    assert main(["--claim", "nope", "--device", "cpu"]) == 2
