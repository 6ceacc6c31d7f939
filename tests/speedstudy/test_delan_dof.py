"""DeLaN's cost against the degrees of freedom (`speedstudy.delan_dof`): the module runs at tiny sizes and
writes a well-formed CSV (default run); the measurement at its real sizes is a benchmark (`-m bench`), which
reports the ratios and asserts no time."""
import csv

import numpy as np
import pytest

from lagbench.speedstudy import delan_dof


def _read(path):
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        return reader.fieldnames, list(reader)


def test_tiny_run_writes_a_well_formed_csv(tmp_path):
    path = tmp_path / "out" / "delan_dof.csv"
    assert delan_dof.main(["--out", str(path), "--dofs", "1,3", "--batch", "4", "--hidden", "4",
                           "--seconds", "0"]) == 0
    header, rows = _read(path)
    assert tuple(header) == delan_dof.COLUMNS
    assert len(rows) == len(delan_dof.FRAMEWORKS) * len(delan_dof.METHODS) * 2
    keys = {(r["framework"], r["method"], int(r["dof"])) for r in rows}
    assert keys == {(f, m, d) for f in delan_dof.FRAMEWORKS for m in delan_dof.METHODS for d in (1, 3)}
    for r in rows:
        assert r["batch"] == "4" and r["hidden"] == "4" and r["dtype"] == "float32"
        us, rate, ratio = float(r["us_per_sample"]), float(r["samples_per_s"]), float(r["ratio"])
        assert np.isfinite([us, rate, ratio]).all() and us > 0 and rate > 0 and ratio > 0
        assert rate == pytest.approx(1e6 / us)
        if r["dof"] == "1":
            assert ratio == 1.0


def test_bad_sizes_raise():
    with pytest.raises(ValueError, match="dofs >= 1"):
        delan_dof.delan_dof_rows(dofs=(0, 2), batch=4, hidden=(4,), seconds=0)
    with pytest.raises(ValueError, match="unknown framework"):
        delan_dof.delan_dof_rows(dofs=(2,), batch=4, hidden=(4,), seconds=0, frameworks=("numpy",))


@pytest.mark.bench
def test_delan_cost_against_dof(tmp_path, capsys):
    """The study at its own sizes (dof 2, 4, 7; batch 1024; 2 x 64): the ratios are printed, never judged."""
    rows = delan_dof.delan_dof_rows()
    delan_dof.write(rows, tmp_path / "delan_dof.csv")
    with capsys.disabled():
        for r in rows:
            print(f"{r['framework']} {r['method']} dof {r['dof']}: {r['us_per_sample']:.3f} us/sample, "
                  f"ratio {r['ratio']:.2f}")
    assert all(np.isfinite(r["ratio"]) for r in rows)
