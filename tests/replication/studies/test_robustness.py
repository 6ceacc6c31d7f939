"""The robustness study (`replication.studies.robustness`, `lagbench robustness`): a tiny run writes the
declared tables and figure inside --out only; the null (zero torque) scores 1 against itself and is never
recommended; the recommendation is the cheapest model within 2x of the best; bad options are one line."""
import numpy as np
import pandas as pd
import pytest

from lagbench.cli import main
from lagbench.replication.studies import control as C
from lagbench.replication.studies import robustness as R
from lagbench.replication.studies.robustness_scenes import Plant, Scene, scene_data

TINY = {"n_train": 2, "n_test": 2, "n_points": 40, "n_refs": 1, "ref_duration": 0.1}


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("robustness")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(R, "SCENES", (Scene("nominal"), Scene("coulomb", 2.0)))
        mp.setattr(R, "SIZES", TINY)
        assert main(["robustness", "--out", str(out), "--steps", "3", "--seeds", "0", "--quiet"]) == 0
    return out


def test_a_tiny_run_writes_the_declared_tables_and_the_figure_inside_out(tiny_run):
    assert [p.name for p in tiny_run.iterdir()] == ["robustness"]
    folder = tiny_run / "robustness"
    df, rec = pd.read_csv(folder / "scenes.csv"), pd.read_csv(folder / "recommendation.csv")
    assert tuple(df.columns) == R.COLUMNS and tuple(rec.columns) == R.REC_COLUMNS
    assert (folder / "advantage.png").stat().st_size > 1000
    assert set(df["scene"]) == set(rec["scene"]) == {"nominal", "coulomb-2"}
    assert set(df["model"]) == {R.NULL, "exact", *R.MODELS} and len(df) == 2 * (2 + len(R.MODELS))
    null, ff = df[df["model"] == R.NULL], df[df["model"] == "ff"]
    assert (null["torque_nmse"] == 1).all() and (null["track_ratio_to_null"] == 1).all()
    assert (ff["torque_ratio_to_ff"] == 1).all() and (df.loc[df["model"] == "exact", "torque_nmse"] == 0).all()
    learned = df[df["model"].isin(list(R.MODELS))]
    assert (learned["params"] > 1000).all() and learned["b0"].notna().sum() == 2
    assert not rec["recommended"].isin([R.NULL, "exact"]).any()
    summary = (folder / "summary.md").read_text().splitlines()   # a row per scene, its pick the recommendation's
    assert len(summary) == 2 + 2 and [row.split(" | ")[-1].rstrip(" |") for row in summary[2:]] == list(rec["recommended"])


def test_a_zero_torque_predictor_is_the_null_and_is_never_recommended():
    scene = Scene("viscous", 2.0)
    plant, test = Plant(scene), scene_data(scene, "test", 2, 40, R.TEST_SEED)
    refs = C.references("test", n=1, duration=0.1)
    zero = R.score(lambda q, v, a: np.zeros_like(q), test, refs, plant)
    null = R.score(None, test, refs, plant)
    assert zero == null and zero["torque_nmse"] == 1.0
    base = {"scene": scene.id, "kind": scene.kind, "magnitude": 2.0, "unit": "-", "framework": "jax", "seed": "0"}
    rows = [{**base, "model": R.NULL, "framework": "numpy", "seed": "-", "params": 0, **null},
            {**base, "model": "zero", "params": 1, **zero},
            {**base, "model": "ff", "params": 4000, "torque_nmse": 0.9, "track_mse": 1.0, "n_diverged": 0}]
    df = R.with_ratios(pd.DataFrame(rows))
    assert df.loc[df["model"] == "zero", "track_ratio_to_null"].item() == 1.0
    assert R.recommend(df)["recommended"].item() == "none"   # nothing clearly beats the null
    df.loc[df["model"] == "ff", "torque_nmse"] = 0.01
    rec = R.recommend(df)
    assert rec["recommended"].item() == "ff" and rec["candidates"].item() == "ff"


def test_the_recommendation_is_the_cheapest_model_within_twice_the_best_error():
    def table(errors):
        return pd.DataFrame([{"scene": "s", "kind": "viscous", "magnitude": 1.0, "framework": "jax", "seed": str(s),
                              "model": m, "params": p, "torque_nmse": e}
                             for m, (p, es) in errors.items() for s, e in enumerate(es)])

    rec = R.recommend(table({"delan": (4600, [0.010, 0.012]), "ff": (4700, [0.05, 0.06]),
                             "delan_dissipation": (4602, [0.008, 0.009])}))
    assert rec["recommended"].item() == "delan" and rec["best_model"].item() == "delan_dissipation"
    assert rec["candidates"].item() == "delan;delan_dissipation"
    rec = R.recommend(table({"delan": (4600, [0.3, 0.3]), "ff": (4700, [0.01, 0.01])}))
    assert rec["recommended"].item() == "ff" and rec["torque_nmse"].item() == 0.01


def test_scenes_in_two_workers_give_the_table_of_one_process(tiny_run, tmp_path):
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(R, "SCENES", (Scene("nominal"), Scene("coulomb", 2.0)))
        mp.setattr(R, "SIZES", TINY)
        assert main(["robustness", "--out", str(tmp_path), "--steps", "3", "--seeds", "0", "--jobs", "2", "--quiet"]) == 0
    one, two = (pd.read_csv(f / "robustness" / "scenes.csv") for f in (tiny_run, tmp_path))
    assert one[["scene", "model", "seed"]].equals(two[["scene", "model", "seed"]])
    numbers = one.select_dtypes("number").columns
    np.testing.assert_allclose(two[numbers].to_numpy(float), one[numbers].to_numpy(float), rtol=1e-4, atol=1e-8)


@pytest.mark.parametrize("option, bad", [("--steps", "0"), ("--seeds", "x"), ("--frameworks", "tf"),
                                         ("--jobs", "0")])
def test_bad_options_are_one_line_naming_the_option_and_write_nothing(tmp_path, capsys, option, bad):
    assert main(["robustness", "--out", str(tmp_path / "o"), option, bad, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and option in err and not (tmp_path / "o").exists()


def test_the_run_reaches_the_report_with_its_settings_table_and_figure(tiny_run, tmp_path):
    import json

    from lagbench.reports.document import Figure, Table
    from lagbench.reports.load import load_results
    from lagbench.reports.sections_robustness import robustness_sections

    settings = json.loads((tiny_run / "robustness" / "study.json").read_text())
    assert settings["steps"] == 3 and settings["seeds"] == [0] and settings["sizes"] == TINY
    (section,) = robustness_sections(load_results(tiny_run), tmp_path)
    table = next(b for b in section.blocks if isinstance(b, Table)).df
    rec = pd.read_csv(tiny_run / "robustness" / "recommendation.csv")
    assert list(table["scene"]) == ["nominal", "coulomb-2"] and list(table["pick"]) == list(rec["recommended"])
    text = " ".join(getattr(b, "text", "") for b in section.blocks)
    assert "3 optimiser steps" in text and "PD alone" in text
    (figure,) = [b for b in section.blocks if isinstance(b, Figure)]
    assert (tmp_path / figure.path).stat().st_size > 1000
    assert robustness_sections(load_results(tmp_path), tmp_path) == []   # no study: no section
