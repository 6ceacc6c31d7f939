"""`reports.verdict_diff`: two runs' verdicts part by part, and the exit status that says whether they agree."""
import json

from lagbench.reports import verdict_diff


def _verdicts(verdict, lo, hi, distance):
    part = {"name": "similar held-out loss", "by_framework": {"jax": verdict},
            "interval": {"jax": {"point": (lo + hi) / 2, "lo": lo, "hi": hi, "distance": distance}}}
    return {"claims": [{"id": "dp_loss", "verdict": verdict, "parts": [part]},
                       {"id": "other", "verdict": "reproduced", "parts": []}]}


def test_the_same_verdicts_agree_and_show_their_intervals_and_distances(tmp_path, capsys):
    a, b = _verdicts("not reproduced", 0.3, 0.4, 1.67), _verdicts("not reproduced", 0.31, 0.42, 1.59)
    df = verdict_diff.rows(a, b, ["dp_loss"])
    assert list(df["part"]) == ["(claim)", "similar held-out loss"] and df["same"].all()
    row = df.iloc[1]
    assert row["interval A"] == "0.35 [0.3, 0.4]" and row["distance B"] == "1.59"
    pa, pb = tmp_path / "a.json", tmp_path / "b.json"
    pa.write_text(json.dumps(a))
    pb.write_text(json.dumps(_verdicts("inconclusive", 0.5, 0.8, 1.2)))
    assert verdict_diff.main([str(pa), str(pa)]) == 0
    assert verdict_diff.main([str(pa), str(pb), "--claims", "dp_loss"]) == 1
    assert "inconclusive" in capsys.readouterr().out
    assert verdict_diff.main([str(pa), str(tmp_path / "missing.json")]) == 2
