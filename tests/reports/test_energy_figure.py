"""The energy figure (`reports.figures.energy_drift`, LNN Fig. 2(b)'s axes): |error| on a log axis, medians over
rollouts and seeds, a diverged rollout counted in the legend and kept out of the line."""
import numpy as np
import pandas as pd

from lagbench.reports import figures as F
from lagbench.reports.load import Unit


def _unit(tmp_path, model, seed, errors):
    folder = tmp_path / model / str(seed)
    folder.mkdir(parents=True)
    t = np.linspace(0, 10, 11)
    rows = [pd.DataFrame({"traj": k, "t": t, "quantity": "energy_err", "value": e}) for k, e in enumerate(errors)]
    pd.concat(rows).to_csv(folder / "timeseries.csv", index=False)
    return Unit("dp_energy", "jax", model, str(seed), folder, str(folder), "ok")


def test_a_blow_up_is_counted_not_averaged(tmp_path, monkeypatch):
    t = np.linspace(0, 10, 11)
    small = [1e-3 * t, 2e-3 * t]
    blown = [1e-3 * t, np.where(t > 5, 2e35, 1e-2 * t)]
    units = [_unit(tmp_path, "lnn", 0, small), _unit(tmp_path, "baseline", 0, blown), _unit(tmp_path, "baseline", 1, small)]
    seen = {}
    real = F.save

    def keep(fig, path):
        ax = fig.axes[0]
        seen.update(scale=ax.get_yscale(), labels=[ln.get_label() for ln in ax.get_lines()],
                    top=max(np.nanmax(ln.get_ydata()) for ln in ax.get_lines()))
        return real(fig, path)
    monkeypatch.setattr(F, "save", keep)
    assert F.energy_drift(units, tmp_path / "e.png")
    assert seen["scale"] == "log" and seen["top"] < 1
    assert any("1 of 4 rollouts diverged" in x for x in seen["labels"] if x.startswith("baseline"))
    assert not any("diverged" in x for x in seen["labels"] if x.startswith("lnn"))


def test_a_model_whose_every_rollout_diverged_is_named_not_drawn(tmp_path):
    t = np.linspace(0, 10, 11)
    units = [_unit(tmp_path, "lnn", 0, [1e-3 * t]), _unit(tmp_path, "baseline", 0, [np.where(t > 0, np.inf, 0.0)] * 2)]
    assert F.energy_drift(units, tmp_path / "e.png")


def test_a_published_value_is_marked_with_its_conditions_for_models_drawn_only(tmp_path, monkeypatch):
    t = np.linspace(0, 10, 11)
    units = [_unit(tmp_path, "lnn", 0, [1e-3 * t])]
    seen = {}
    real = F.save

    def keep(fig, path):
        seen.update({ln.get_label(): ln.get_ydata() for ln in fig.axes[0].get_lines()})
        return real(fig, path)
    monkeypatch.setattr(F, "save", keep)
    assert F.energy_drift(units, tmp_path / "e.png", published={"lnn": (0.0043, "final time; t_end 100"),
                                                                 "baseline": (0.074, "final time")})
    marked = [k for k in seen if k.startswith("published")]
    assert marked == ["published lnn: 0.0043 (final time; t_end 100)"]
    assert np.allclose(seen[marked[0]], 0.0043)
