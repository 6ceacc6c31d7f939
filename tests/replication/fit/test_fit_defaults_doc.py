"""docs/fit.md's table of `fit`'s defaults per model kind says what `replication.fit.kind_defaults` gives."""
import re
from itertools import takewhile
from pathlib import Path

import pytest

from lagbench.replication.fit import kind_defaults

DOC = Path(__file__).resolve().parents[3] / "docs" / "fit.md"
ROWS = {"lnn": ("lnn", "acceleration"), "baseline (q̈)": ("baseline", "acceleration"), "hnn": ("hnn", "hamiltonian"),
        "delan (τ or q̈)": ("delan", "inverse_dynamics"), "baseline (τ)": ("baseline", "inverse_dynamics")}


def _table() -> dict:
    text = DOC.read_text()
    start = text.index("| kind (data) |")
    lines = list(takewhile(lambda line: line.startswith("|"), text[start:].splitlines()))
    rows = [line.split("|")[1:-1] for line in lines[2:]]
    return {cells[0].strip(): [c.strip() for c in cells] for cells in rows}


def test_every_kind_has_a_row():
    assert set(_table()) == set(ROWS)
    assert {ROWS[k] for k in ROWS} | {("delan", "acceleration")} == set(kind_defaults.SOURCES)


@pytest.mark.parametrize("label", sorted(ROWS))
def test_a_row_says_what_the_kind_gets(label):
    kind, task = ROWS[label]
    d = kind_defaults.defaults(kind, task)
    _, source, budget, widths, rate, loss, restarts, guard, scale = _table()[label]
    claim, entry, _ = kind_defaults._entry(kind, task)
    assert source.startswith(f"claim {claim.number}, {entry.label}")
    factor = kind_defaults.ON_RECORDINGS.get((kind, task), 1)
    switch = kind_defaults.NOISY_RECORDINGS.get((kind, task))
    below = f" with position noise below {switch:g} rad" if switch is not None else ""
    on_file = f" ({factor} x the steps on a trajectory file{below})" if factor != 1 else ""
    assert budget == f"{d['steps']:,} x {d['batch']}".replace(",", " ") + on_file
    w = d["hidden"]
    assert len(set(w)) == 1 and widths == f"{w[0]} x {len(w)}, {d['activation']}"
    assert float(rate.split(",")[0]) == pytest.approx(d["lr"])
    assert ("one-cycle" in rate) == (d["schedule"] == "onecycle")
    assert (f"from phase {d['lr_start']:g}" in rate) == (d["schedule"] == "onecycle" and d["lr_start"] != 0.2)
    assert loss == d["loss"].upper()
    if d["restarts"] is None:
        assert restarts == "none"
    else:
        m = re.match(r"(\d+) \((\d+)\), (\d+)", restarts)
        assert m and tuple(map(int, m.groups())) == (d["restarts"], d["restart_keep"], d["restart_batch"])
        if "at 2/3" in restarts:
            assert d["restart_fraction"] == pytest.approx(2 / 3, abs=1e-3) and d["restart_lr_ratio"] == pytest.approx(0.1)
    assert guard == ("none" if d["guard_clip"] is None else f"{d['guard_clip']:g}, {d['guard_skip']:g}")
    assert scale == (d["input_scale"] or "none")
