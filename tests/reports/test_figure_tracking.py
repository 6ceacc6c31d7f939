"""Claim 12's tracking figure (`reports.figures_delan.tracking`) and claim 13's learning-online figure
(`reports.figures_delan.online_learning`): drawn from the units' arrays, one line per learned controller (per
unit for claim 13, a diverged window left out), nothing when no unit holds the arrays."""
from dataclasses import dataclass

import numpy as np

from lagbench.reports import figures_delan as FD


@dataclass
class StubUnit:
    model: str
    framework: str
    seed: str
    arr: dict
    status: str = "ok"
    result: dict | None = None

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


def test_the_online_learning_figure_draws_each_unit(tmp_path):
    end = np.arange(1, 7) * 0.5
    units = [StubUnit(m, fw, str(seed), {"window_end": end, "window_ratio": np.r_[np.inf, 2.0 / (end[1:] * k)]},
                      result={"eval_config": {"threshold": 0.1}})
             for m, k in (("delan", 1.0), ("ff", 10.0)) for fw in ("jax", "torch") for seed in (1000, 1001)]
    path = tmp_path / "online.png"
    assert FD.online_learning(units, path) and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not FD.online_learning([StubUnit("delan", "jax", "1000", {"test_t": end})], tmp_path / "none.png")
    assert not (tmp_path / "none.png").exists()
