"""The adopted tuning: the records of `tuned.json` and which one serves a model of a claim under a profile.

`tuned.json` (beside this file): {claim id: {profile: record}}, a record being {"ledger_hash" (the
`canonical_hash` of the adopted ledger.json), "split" ("dev", the only split a choice may read), "seeds",
"frameworks", "configs" (configurations tried per model), "search" (the knobs and their values), "adopted"
(the date), "ledger" (its file, where the adopted search names it), "edge_limits" (where the search declared
them: the knob bounds of its edge step, `search.EDGE_LIMITS`), "models": {label: {"knobs",
"configs_tried", "score", "confirm_seeds"}}}. Written by
`python -m lagbench.replication.tuning.adopt OUT/ledger.json` from a ledger of `lagbench tune`.

`records()`: the file's records (the one reader of the file).
`with_knobs(entry, base, profile, knobs) -> ModelEntry`: the entry with the knob values applied under
`profile` only (peak rate, the scouting round's with it, as a multiple of the entry's own; every hidden
width as a multiple): the tuning search's configurations and an adopted choice are both this.
`choice(claim, entry, profile, adopted) -> Adopted | None`: the adopted record that serves a model of the claim
as written under the profile, in `adopted` (the records): the claim's own record for the profile, and under a
profile the claim is silent about (a model that runs there exactly as under quick: `full` for most claims),
quick's, the search having run at that profile's budget too. A claim whose models are another claim's
trainings (`SHARED`) takes that claim's choices (under the profile whose protocol it trains with), so that
their trainings stay one; a variant takes its paper model's choice (its departure is all that differs), and a
positive control with `tuned_as` that of the model it vouches for. None: the model keeps its registered
(hand-chosen) setting.
Applying a choice to a claim is `resolved.resolved`'s, the one place where the written claim becomes what runs.
"""
from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field
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


@dataclass(frozen=True)
class Adopted:
    """The adopted choice a model takes: where it stands in tuned.json (`claim`, `profile`, `label`: another
    claim's, profile's or model's where the model shares that training) and what the search chose."""

    claim: str
    profile: str
    label: str
    knobs: dict            # {"lr": multiple of the registered peak rate, "width": multiple of the widths}
    configs_tried: int
    confirm_seeds: tuple
    score: float | None    # the chosen configuration's development score
    ledger_hash: str
    ledger: str | None     # the ledger's file, where the record names it
    split: str             # "dev"
    seeds: tuple           # the search's seeds
    edge_limits: dict = field(default_factory=dict)   # the bounds of the search's edge step, where declared

    def describe(self) -> dict:
        return {"claim": self.claim, "profile": self.profile, "label": self.label, "knobs": dict(self.knobs),
                "configs_tried": self.configs_tried, "confirm_seeds": list(self.confirm_seeds), "score": self.score,
                "ledger_hash": self.ledger_hash, "ledger": self.ledger, "split": self.split, "seeds": list(self.seeds),
                **({"edge_limits": dict(self.edge_limits)} if self.edge_limits else {})}


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


def _record(claim_id: str, profile: str, adopted: dict) -> tuple[str, str, dict | None, dict]:
    """(the claim and profile whose record serves the claim under the profile, that record, the label map)."""
    source, names, profiles = SHARED.get(claim_id, (claim_id, {}, {}))
    at = profiles.get(profile, profile)
    return source, at, adopted.get(source, {}).get(at), names


def _same_as_quick(claim, entry, profile: str) -> bool:
    """Whether the entry runs under `profile` exactly as under quick (a claim silent about the profile): then
    quick's adopted search is one at this profile's budget too, and its choice serves it."""
    if profile == "quick" or not (entry.runs_in(profile) and entry.runs_in("quick")):
        return False
    if per_profile(claim.protocols, profile) is None or per_profile(claim.protocols, "quick") is None:
        return False
    return (entry.widths(profile) == entry.widths("quick") and entry.spec_fields(profile) == entry.spec_fields("quick")
            and entry.protocol(claim.protocol(profile), profile) == entry.protocol(claim.protocol("quick"), "quick"))


def choice(claim, entry, profile: str, adopted: dict) -> Adopted | None:
    """The adopted choice that serves `entry` (a model of `claim` as written) under `profile`, or None."""
    source, at, rec, names = _record(claim.id, profile, adopted)
    if rec is None and _same_as_quick(claim, entry, profile):
        source, at, rec, names = _record(claim.id, "quick", adopted)
    paper = claim.paper_model(entry.tuned_as or entry.label)
    label = names.get(paper, paper)
    chosen = (rec or {}).get("models", {}).get(label)
    if not chosen:
        return None
    return Adopted(claim=source, profile=at, label=label, knobs=dict(chosen["knobs"]),
                   configs_tried=chosen["configs_tried"], confirm_seeds=tuple(chosen.get("confirm_seeds", [])),
                   score=chosen.get("score"), ledger_hash=rec["ledger_hash"], ledger=rec.get("ledger"),
                   split=rec["split"], seeds=tuple(rec["seeds"]), edge_limits=dict(rec.get("edge_limits") or {}))


def equal(tuning_: dict) -> bool:
    """Whether every trained model got the same number of configurations."""
    return len({t["configs_tried"] for t in tuning_.values()}) <= 1
