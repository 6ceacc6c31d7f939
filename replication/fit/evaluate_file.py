"""`lagbench evaluate --fitted DIR --data FILE`: fitted models judged on a new data file.

`evaluate(model, data, out, framework=None, system=None, substeps=None, window=None, polyorder=None,
energy=None, device="auto", horizon=None, on_progress=None, time_unit=None)`
-> [result dict]. `model` is a fit's unit folder or a `lagbench fit` results folder (every fitted model
in it, side by side). Each model is loaded by `load.load_fitted` (checksums verified; in `framework`,
default the one it was trained in: parameters load in either), the data file is prepared as a test file
(`rows.prepare(kind="test")`, derivatives of a trajectory file by the fit's own window rule (a fit that
chose its window from its data, `--window auto`, has this file's chosen from this file's data the same way),
polyorder and time unit unless given; with a system, the step checked against its time scale,
`replication.fit.time_base`) and evaluated by the fit routine (`evaluate.eval_fit`: one-step errors per
component, rollouts, energies with `system` or `energy` ("module:function"), DeLaN's decomposition). Written as units of a claim
"evaluate": `OUT/units/evaluate/<framework>/<model>/seed<k>/` (result.json, one_step.csv, rollouts.csv,
timeseries.csv, arrays.npz; `lagbench report` renders them) and OUT/data/ (the prepared rows). A verified
earlier evaluation of the same model, data and options is returned as is; another one there is kept,
renamed `superseded-<time>-seed<k>`. Every option and every model is checked before anything is written.
A data file that is the fit's training file, or holds only its training rows, is refused; one that holds some
is evaluated with their count recorded (`eval_config["training_rows"]`: `rows.Overlap`; `rows.training_rows_check`).
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

from lagbench.files import results as R
from lagbench.files import user_data
from lagbench.replication.claims.base import Claim, ModelEntry
from lagbench.replication.fit import dissipation, time_base, trajectories
from lagbench.replication.fit import options as fit_options
from lagbench.replication.fit import rows as fit_data
from lagbench.replication.fit.load import fitted_folders, load_fitted
from lagbench.replication.fit.task import LOSS_NAMES, file_derivatives
from lagbench.replication.run.units import Unit, run_unit


def _check(framework, system, substeps, window, polyorder, horizon, time_unit):
    given = {"framework": framework, "substeps": substeps, "system": system, "horizon": horizon, "time_unit": time_unit}
    fit_options.check({k: v for k, v in given.items() if v is not None})
    if window is not None or polyorder is not None:
        trajectories.check_options(window or trajectories.AUTO, polyorder or trajectories.POLYORDER)


@R.writes
def evaluate(model, data, out="results/evaluate", framework=None, system=None, substeps=None, window=None,
             polyorder=None, energy=None, device="auto", horizon=None, on_progress=None, time_unit=None) -> list[dict]:
    _check(framework, system, substeps, window, polyorder, horizon, time_unit)
    path = str(Path(data).resolve())
    digest, raw = user_data.read(path)
    has_tau = "tau" in raw
    fits = [load_fitted(f) for f in fitted_folders(model)]
    for f in fits:   # the time base of each fit's evaluation, before anything is written
        fcfg = f.result.get("eval_config") or {}
        unit = time_unit or (fcfg.get("derivatives") or {}).get("time_unit", "s")
        time_base.check_unit(f"--data {data}", raw, system or fcfg.get("system"), unit)
    if energy:
        from lagbench.replication.fit.evaluate import energy_function

        energy_function({"energy": energy}, fits[0].spec.dof)
    for f in fits:
        if (f.task == "inverse_dynamics") != has_tau:
            raise ValueError(f"--data {data}: {'has' if has_tau else 'lacks'} tau columns, but the fit in {f.folder} "
                             f"was trained {'with' if f.task == 'inverse_dynamics' else 'without'} them")
    from lagbench.replication.training import device as dev

    dev.apply(device, sorted({framework or f.result["framework"] for f in fits}))   # before anything is written
    shared = {}   # the fit's training rows in the file: refused when it is all or the very file, else recorded
    for f in fits:
        unit = time_unit or ((f.result.get("eval_config") or {}).get("derivatives") or {}).get("time_unit", "s")
        shared[f.folder] = fit_data.training_rows_check(path, f"--data {data}", time_base.in_seconds(raw, unit), digest,
                                                        f.result, f.folder)
    out = R.output_folder(out, "--out")
    from lagbench.replication.run.runner import is_current

    done = []
    for f in fits:
        r = f.result
        deriv = (r.get("eval_config") or {}).get("derivatives") or {}
        p = polyorder or deriv.get("polyorder", trajectories.POLYORDER)
        g = deriv.get("gaps", "interpolate")
        unit = time_unit or deriv.get("time_unit", "s")
        used = file_derivatives(path, window or trajectories.rule_of(deriv), p, g, unit)   # "auto": this file's own
        prep = fit_data.prepare(out, path, window=used["window"], polyorder=p, dtype=f.spec.dtype, kind="test", gaps=g,
                                time_unit=unit)
        if prep.dof != f.spec.dof:
            raise ValueError(f"--data {data}: has {prep.dof} degrees of freedom, the model in {f.folder} {f.spec.dof}")
        fields = {k: v for k, v in r["model_spec"].items() if k not in ("hidden", "dtype")}
        entry = ModelEntry(r["model"], fields, hidden=tuple(f.spec.hidden), train=False)
        fcfg = r.get("eval_config") or {}
        cfg = {"heldout": False, "test": prep.reference, "system": system or fcfg.get("system"),
               "energy": energy or fcfg.get("energy"),
               "substeps": substeps or (r.get("eval_config") or {}).get("substeps", 2), "model": str(f.folder.resolve()),
               "model_checksum": r["checksum"], "trained_in": r["framework"], "derivatives": {**used, **({"gaps": g} if g != "interpolate" else {}),
                                                                     **({"time_unit": unit} if unit != "s" else {})},
               "rows": prep.counts, "trajectories": prep.trajectories, "source": prep.source}
        if r["model_spec"].get("dissipation"):   # as a fit records it (`replication.fit.task`)
            cfg["friction_gate"] = dissipation.GATE
        if (horizon or fcfg.get("horizon")) is not None:   # recorded only when set: the others keep their keys
            cfg["horizon"] = float(horizon or fcfg["horizon"])
        if shared[f.folder] is not None:   # recorded only when the file holds some training rows
            cfg["training_rows"] = dataclasses.asdict(shared[f.folder])
        loss = f.protocol.loss if f.protocol.loss in LOSS_NAMES else "l1"
        claim = Claim(id="evaluate", number=0, paper="user", section="-", title=f"{r['model']} on {Path(data).name}",
                      system=cfg["system"] or Path(data).name, models=(entry,), protocols={"quick": f.protocol},
                      evaluate="fit", metric=f"test_{loss}", metric_label=f"test {LOSS_NAMES[loss]}", published={},
                      verdict_rule="none (user data)", parts=(), eval_config={"quick": cfg})
        unit = Unit(claim, entry, framework or r["framework"], int(r["seed"]), "quick")
        if is_current(unit, out):
            done.append(dict(R.load_result(unit.folder(out)), reused=True, folder=str(unit.folder(out))))
        else:
            done.append(dict(run_unit(unit, out, on_progress=on_progress), folder=str(unit.folder(out))))
    return done
