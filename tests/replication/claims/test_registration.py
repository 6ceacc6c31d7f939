"""Frozen protocols (`replication.claims.registration`): every claim's protocol under every profile
matches a committed registration; changing a model's protocol, the evaluation or a rule's threshold
changes the hash and leaves the claim unregistered until a new dated line discloses the change."""
import dataclasses

import pytest

from lagbench.replication.claims import CLAIMS, PROFILES, get
from lagbench.replication.claims import registration as reg


def test_every_claim_and_profile_is_registered():
    missing = [f"{c.id}/{p}" for c in CLAIMS.values() for p in PROFILES if not reg.status(c, p)["registered"]]
    assert not missing, ("protocols changed without a registration (run `python -m lagbench.replication.claims.registration "
                         f"--note ...` and say why): {missing}")


def test_a_changed_protocol_evaluation_or_threshold_is_unregistered(monkeypatch):
    claim = get("dp_loss")
    before = reg.status(claim, "quick")
    assert before["registered"] and before["frozen"]
    longer = dataclasses.replace(claim, protocols={**claim.protocols, "quick": claim.protocols["quick"].replace(steps=1)})
    other_eval = dataclasses.replace(claim, eval_config={**claim.eval_config, "quick": {"n_ics": 1}})
    from lagbench.replication.claims.rules import similar
    part = dataclasses.replace(claim.parts[0], rule=similar("lnn", "baseline", 3.5, claim.metric))
    looser = dataclasses.replace(claim, parts=(part, *claim.parts[1:]))
    hashes = {reg.protocol_hash(c, "quick") for c in (claim, longer, other_eval, looser)}
    assert len(hashes) == 4
    for changed in (longer, other_eval, looser):
        s = reg.status(changed, "quick")
        assert not s["registered"] and s["frozen"] is None and s["registrations"] == before["registrations"]


def test_a_rules_comparison_code_or_level_is_part_of_its_hash(monkeypatch):
    """The same rule, name and thresholds, with other comparison code (a helper it reaches in rules.py or
    stats.py) or another interval level, is a new protocol."""
    from lagbench.replication.claims import rules, stats

    claim = get("dp_energy")
    before = reg.protocol_hash(claim, "quick")

    def _below(iv, t):   # the same name, a looser comparison
        return "reproduced" if iv.hi <= t else "not reproduced" if iv.lo >= t else "inconclusive"
    monkeypatch.setattr(rules, "_below", _below)
    assert reg.protocol_hash(claim, "quick") != before
    monkeypatch.undo()
    assert reg.protocol_hash(claim, "quick") == before
    monkeypatch.setattr(stats, "LEVEL", 0.8)
    assert reg.protocol_hash(claim, "quick") != before
    monkeypatch.undo()
    monkeypatch.setattr(stats, "_log_t", lambda a, b, level: (1.0, 1.0, 1.0, 1.0))
    assert reg.protocol_hash(claim, "quick") != before


def test_register_appends_a_dated_line_for_a_changed_protocol_only(tmp_path, monkeypatch):
    monkeypatch.setattr(reg, "FILE", tmp_path / "registrations.json")
    reg.registrations.cache_clear()
    try:
        assert len(reg.register("first", today="2026-01-01")) == len(CLAIMS) * len(PROFILES)
        assert reg.register("again", today="2026-01-02") == []
        claim = get("dp_loss")
        monkeypatch.setitem(claim.protocols, "quick", claim.protocols["quick"].replace(steps=1))
        added = reg.register("fewer steps", today="2026-01-03")   # claim 2 includes claim 1's PROTOCOLS record
        assert "dp_loss/quick" in added and all(a.endswith("/quick") for a in added)
        s = reg.status(claim, "quick")
        assert s["registered"] and s["frozen"] == "2026-01-03" and s["note"] == "fewer steps" and s["registrations"] == 2
    finally:
        reg.registrations.cache_clear()


def test_verdicts_carry_the_registration_they_are_given():
    """The judge reads no file: the registrations and the adopted tuning it is given decide its record."""
    import pandas as pd

    from lagbench.replication.claims import tuned
    from lagbench.replication.claims.verdicts import judge

    claim, none = get("dp_loss"), pd.DataFrame(columns=["claim", "framework", "model", "seed", "status"])
    committed, adopted = reg.registrations(), tuned.records()
    v = judge(claim, none, "quick", committed, adopted)
    assert v["preregistration"]["registered"] and v["preregistration"]["protocol_hash"] == reg.protocol_hash(claim, "quick")
    assert not judge(claim, none, "quick", {}, adopted)["preregistration"]["registered"]
    # without claim 1's adopted choice its models run as written: another protocol, registered under none of its lines
    hand = judge(claim, none, "quick", committed, {})["preregistration"]
    assert not hand["registered"] and hand["protocol_hash"] != v["preregistration"]["protocol_hash"]
    assert all(t["configs_tried"] == 0 for t in hand["tuning"].values())
    assert "preregistration" not in judge(claim, none, "quick")   # nothing given: no record read behind its back
    with pytest.raises(TypeError, match="adopted"):
        judge(claim, none, "quick", committed)


def test_every_claim_spells_out_every_profile():
    """No profile inherits another's settings: each claim names its protocol and seed count in every profile,
    and each model its widths in every profile it runs in."""
    for c in CLAIMS.values():
        for p in PROFILES:
            assert p in c.protocols and p in c.seeds, f"{c.id}: no protocol or seeds for {p}"
            for m in c.models:
                if m.runs_in(p) and isinstance(m.hidden, dict):
                    assert p in m.hidden, f"{c.id}/{m.label}: no widths for {p}"


def test_no_claim_imports_another_claim():
    """Claims share settings through constant modules (double_pendulum.py, pace_study.py), never by importing
    each other."""
    import ast
    from pathlib import Path

    folder = Path(__file__).resolve().parents[3] / "replication" / "claims"
    claims = {f.stem for f in folder.glob("*.py") if "\nCLAIM = Claim(" in f.read_text()}
    assert len(claims) == len(CLAIMS)
    for name in claims:
        tree = ast.parse((folder / f"{name}.py").read_text())
        used = {a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module == "lagbench.replication.claims"
                for a in n.names}
        used |= {n.module.rsplit(".", 1)[1] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module
                 and n.module.startswith("lagbench.replication.claims.")}
        assert not used & (claims - {name}), f"{name} imports {used & claims}"
