"""Claim 12's tracking figure (`reports.figures_delan.tracking`): drawn from the units' arrays, one line per
learned controller, nothing when no unit holds the arrays."""
from dataclasses import dataclass

import numpy as np

from reports import figures_delan as FD


@dataclass
class StubUnit:
    model: str
    framework: str
    seed: str
    arr: dict
    status: str = "ok"

    def arrays(self):
        return self.arr


def test_the_tracking_figure_draws_each_controller(tmp_path):
    t = np.linspace(0, 1, 50)
    ref = np.c_[np.sin(t), np.cos(t)]
    units = [StubUnit(m, fw, "1000", {"test_t": t, "test_q_ref": ref, "test_q": ref + err})
             for m, err in (("delan", 1e-3), ("ff", 1e-2)) for fw in ("jax", "torch")]
    path = tmp_path / "tracking.png"
    assert FD.tracking(units, path) and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not FD.tracking([StubUnit("delan", "jax", "1000", {"tau_true": ref})], tmp_path / "none.png")
    assert not (tmp_path / "none.png").exists()
