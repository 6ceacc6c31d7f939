"""Protocols chosen by `lagbench tune`: a claim's models with the knob values its adopted search chose.

`tuned.json` (beside this file): {claim id: {profile: record}}, a record being {"ledger_hash" (the
`canonical_hash` of the adopted ledger.json), "split" ("dev", the only split a choice may read), "seeds",
"frameworks", "configs" (configurations tried per model), "search" (the knobs and their values), "adopted"
(the date), "ledger" (its file, where the adopted search names it), "models": {label: {"knobs",
"configs_tried", "score", "confirm_seeds"}}}. Written by
`python -m lagbench.replication.tuning.adopt OUT/ledger.json` from a ledger of `lagbench tune`.

`with_knobs(entry, base, profile, knobs) -> ModelEntry`: the entry with the knob values applied under
`profile` only (peak rate, the scouting round's with it, as a multiple of the entry's own; every hidden
width as a multiple): the tuning search's configurations and an adopted choice are both this.
`apply(claim) -> Claim`: the claim with each adopted model's knobs applied under each adopted profile, and
under a profile the claim is silent about (a model that runs there exactly as under quick: `full` for most
claims), quick's choice, the search having run at that profile's budget too.
A claim whose models are another claim's trainings (`SHARED`) takes that claim's choices (under the profile
whose protocol it trains with), so that their trainings stay one; a variant takes its paper model's choice
(its departure is all that differs), and a positive control with `tuned_as` that of the model it vouches
for. Models and profiles without a record keep their registered
(hand-chosen) setting.
`tuning(claim, profile) -> {label: {...}}`: for verdicts.json and the report, per trained model the
configurations its protocol was chosen among, and the split they were scored on (0 and None: by hand).
"""
from __future__ import annotations

import dataclasses
import json
from functools import lru_cache
from pathlib import Path

from lagbench.replication.claims.base import PROFILES, per_profile

FILE = Path(__file__).with_name("tuned.json")
# claim -> (the claim whose tuning it takes, {its label: that claim's label}, {its profile: that claim's
# profile, where it trains under another profile's protocol}); the claims share trainings. Claim 11's `full`
# trains under claim 1's quick protocol at quick's widths (`precision.PROTOCOLS`), so quick's search chose for it.
SHARED = {"dp_energy": ("dp_loss", {}, {}), "delan_tracking": ("delan_arm", {}, {}),
          "precision": ("dp_loss", {f"{m}_{d}": m for m in ("lnn", "baseline") for d in ("f32", "f64")},
                        {"full": "quick"})}


# claims whose models learn inside their evaluation (claim 13's online learners, `train=False`): the learning
# rate and widths they learn with are their protocol's and their spec's, searched and adopted as a training's
LEARNS_IN_EVALUATION = ("online",)


def searched(claim, entry, profile: str) -> bool:
    """Whether the entry is one of the claim's searched models under the profile: one that trains (offline, or
    online inside its evaluation)."""
    return entry.runs_in(profile) and (entry.train or claim.evaluate in LEARNS_IN_EVALUATION)


def scaled_widths(widths, factor: float) -> tuple:
    """Every hidden width times the width knob, rounded, at least 1."""
    return tuple(max(1, int(round(w * factor))) for w in widths)


def with_knobs(entry, base, profile: str, knobs: dict):
    p = entry.protocol(base, profile)
    change = {"schedule.lr": p.schedule.lr * knobs["lr"]}
    if p.scouting:
        change["scouting.schedule.lr"] = p.scouting.schedule.lr * knobs["lr"]
    per = dict(per_profile({k: v for k, v in entry.overrides.items() if k in PROFILES}, profile, {}))
    hidden = {q: entry.widths(q) for q in PROFILES}
    hidden[profile] = scaled_widths(entry.widths(profile), knobs["width"])
    return dataclasses.replace(entry, overrides={**entry.overrides, profile: {**per, **change}}, hidden=hidden)


@lru_cache(maxsize=1)
def records() -> dict:
    """The adopted records. The file ships with the package: without it every claim would silently run its
    hand-chosen protocols under hashes that are registered too, so its absence is an error."""
    if not FILE.is_file():
        raise RuntimeError(f"{FILE} is missing: the install lacks the adopted tuning; reinstall lagbench")
    return json.loads(FILE.read_text())


def _record(claim_id: str, profile: str) -> tuple[dict | None, dict]:
    """The adopted record that serves the claim under the profile, and the label map into it."""
    source, names, profiles = SHARED.get(claim_id, (claim_id, {}, {}))
    return records().get(source, {}).get(profiles.get(profile, profile)), names


def _chosen(claim, rec: dict | None, names: dict, label: str) -> dict | None:
    """The record's choice for a model: a variant (a departure from the paper) takes its paper model's, so
    that the departure is all that tells them apart; a model with `tuned_as` (a positive control) takes
    that model's."""
    entry = next((m for m in claim.models if m.label == label), None)
    label = (entry.tuned_as if entry is not None and entry.tuned_as else label)
    paper = {variant: p for v in claim.variants for p, variant in v.replaces}.get(label, label)
    return (rec or {}).get("models", {}).get(names.get(paper, paper))


def _same_as_quick(claim, entry, profile: str) -> bool:
    """Whether the entry runs under `profile` exactly as under quick (a claim silent about the profile): then
    quick's adopted search is one at this profile's budget too, and its choice serves it."""
    if profile == "quick" or not (entry.runs_in(profile) and entry.runs_in("quick")):
        return False
    if per_profile(claim.protocols, profile) is None or per_profile(claim.protocols, "quick") is None:
        return False
    return (entry.widths(profile) == entry.widths("quick") and entry.spec_fields(profile) == entry.spec_fields("quick")
            and entry.protocol(claim.protocol(profile), profile) == entry.protocol(claim.protocol("quick"), "quick"))


def _serving(claim, entry, profile: str) -> tuple[dict | None, dict]:
    """The adopted record that serves the entry under the profile (its own, else quick's where the entry runs
    as under quick), and the label map into it."""
    rec, names = _record(claim.id, profile)
    if rec is None and _same_as_quick(claim, entry, profile):
        rec, names = _record(claim.id, "quick")
    return rec, names


def apply(claim):
    models = list(claim.models)
    for profile in PROFILES:
        if per_profile(claim.protocols, profile) is None:
            continue
        base = claim.protocol(profile)
        for i, m in enumerate(models):
            rec, names = _serving(claim, claim.models[i], profile)   # judged on the claim as written
            chosen = _chosen(claim, rec, names, m.label)
            if chosen and searched(claim, m, profile):
                models[i] = with_knobs(m, base, profile, chosen["knobs"])
    return dataclasses.replace(claim, models=tuple(models))


def tuning(claim, profile: str) -> dict:
    from lagbench.replication.claims import untuned

    try:
        written = untuned(claim.id)   # whether a profile runs as quick is judged on the claim as written
    except KeyError:
        written = claim
    out = {}
    for m in claim.models:
        if not searched(claim, m, profile):
            continue
        entry = next((w for w in written.models if w.label == m.label), m)
        rec, names = _serving(written, entry, profile)
        chosen = _chosen(claim, rec, names, m.label)
        out[m.label] = ({"configs_tried": chosen["configs_tried"], "scored_on": rec["split"], "knobs": chosen["knobs"],
                         "seeds": rec["seeds"], "confirm_seeds": chosen.get("confirm_seeds", []),
                         "ledger_hash": rec["ledger_hash"]} if chosen else
                        {"configs_tried": 0, "scored_on": None, "knobs": None, "seeds": [], "confirm_seeds": [],
                         "ledger_hash": None})
    return out


def equal(tuning_: dict) -> bool:
    """Whether every trained model got the same number of configurations."""
    return len({t["configs_tried"] for t in tuning_.values()}) <= 1
