"""A unit's files as bytes and back (the Ray executor's driver writes what its workers return)."""
import pandas as pd
import pytest

from lagbench.files import results as R
from lagbench.replication.run import unit_files


def unit_folder(root, name="units/c/jax/m/seed0"):
    folder = root / name
    files = {"train_log.csv": R.write_csv(folder / "train_log.csv", pd.DataFrame({"step": [0, 1]}))}
    R.write_json(folder / "result.json", {"status": "ok", "files": files}, checksum=True)
    return folder


def test_files_travel_as_bytes_and_are_written_verified(tmp_path):
    unit_folder(tmp_path / "worker")
    files = unit_files.collect(tmp_path / "worker")
    assert sorted(files) == ["units/c/jax/m/seed0/result.json", "units/c/jax/m/seed0/train_log.csv"]
    written = unit_files.write(tmp_path / "driver", files)
    assert written == [tmp_path / "driver" / "units/c/jax/m/seed0"]
    assert R.load_result(written[0])["status"] == "ok"


def test_a_folder_without_its_result_is_not_written(tmp_path):
    assert unit_files.write(tmp_path, {"units/c/jax/m/seed0/train_log.csv": b"step\n0\n"}) == []
    assert list(tmp_path.iterdir()) == []


def test_bytes_that_do_not_match_their_result_are_refused(tmp_path):
    unit_folder(tmp_path / "worker")
    files = unit_files.collect(tmp_path / "worker")
    files["units/c/jax/m/seed0/train_log.csv"] = b"step\n7\n"
    with pytest.raises(R.CorruptResult):
        unit_files.write(tmp_path / "driver", files)


@pytest.mark.parametrize("path", ["../units/x/result.json", "/etc/result.json", "units/../../x/result.json",
                                  "elsewhere/result.json"])
def test_paths_outside_the_results_folder_are_refused(tmp_path, path):
    with pytest.raises(ValueError, match="refused"):
        unit_files.write(tmp_path / "out", {path: b"{}"})
    assert not (tmp_path / "out").exists()


def test_a_run_that_continued_a_fallback_scout_records_the_samples_it_trained(tmp_path, monkeypatch):
    """A restarts' fallback (`Scouting.fallback`) trains a second continuation: the unit's train_samples are
    the samples trained, not the protocol's budget."""
    from lagbench.replication.run import runner, units
    from lagbench.replication.training.scouting import budget_samples

    (u,) = runner.plan("smoke", claims=["dp_loss"], frameworks=("jax",), models=["baseline"], seeds=1)
    real, budget = units.train_cached, budget_samples(u.protocol())

    def fell_back(*args, **kwargs):
        o = real(*args, **kwargs)
        o.scouting = {**o.scouting, "continued": [2, 3], "continuation_tail_loss": [9.0, 1.0]}
        o.samples = budget + 7
        return o
    assert units.run_unit(u, tmp_path)["train_samples"] == budget   # as planned
    monkeypatch.setattr(units, "train_cached", fell_back)
    assert units.run_unit(u, tmp_path / "b")["train_samples"] == budget + 7
