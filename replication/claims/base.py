"""The declarative claim record.

A `Claim` names a paper result and everything needed to check it: the system, the models (each a
`ModelEntry`: a label, ModelSpec fields, protocol overrides), the protocol per profile, the
evaluation routine (a name in `replication.evaluate.EVALUATIONS`), the metric the verdict reads,
the published values, and the verdict rule (a function of {model label: mean metric} for one
framework, returning (verdict, reason)).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from replication.protocol import Protocol

PROFILES = ("smoke", "quick", "paper")
VERDICTS = ("reproduced", "partly", "not reproduced", "not run")


@dataclass(frozen=True)
class ModelEntry:
    """One model of a claim. `spec` holds ModelSpec fields except dof and dtype (taken from the system
    and the protocol); `hidden` may map a profile to widths; `overrides` change the claim's protocol
    for this model (another data recipe, task, loss, learning rate, pool size...), optionally per
    profile as {profile: {...}}; `train=False` marks a model evaluated without training; `profiles` limits
    the profiles the model runs in."""

    label: str
    spec: dict
    hidden: dict | tuple = ()
    overrides: dict = field(default_factory=dict)
    train: bool = True
    profiles: tuple = PROFILES   # the profiles this model runs in

    def widths(self, profile: str) -> tuple:
        h = self.hidden.get(profile, ()) if isinstance(self.hidden, dict) else self.hidden
        return tuple(h)

    def protocol(self, base: Protocol, profile: str) -> Protocol:
        common = {k: v for k, v in self.overrides.items() if k not in PROFILES}
        per = self.overrides.get(profile, {})
        return base.replace(**{**common, **per}) if (common or per) else base


@dataclass(frozen=True)
class Claim:
    id: str
    number: int
    paper: str
    section: str
    title: str
    system: str
    models: tuple
    protocols: dict          # profile -> Protocol
    evaluate: str
    metric: str
    metric_label: str
    published: dict
    verdict_rule: str
    verdict: Callable
    seeds: dict = field(default_factory=lambda: {"smoke": 1, "quick": 3, "paper": 3})
    eval_config: dict = field(default_factory=dict)   # profile -> dict of evaluation settings
    verdict_metrics: tuple = ()   # if set, the verdict gets {label: tuple of these metrics' means}

    def entry(self, label: str) -> ModelEntry:
        for m in self.models:
            if m.label == label:
                return m
        raise KeyError(f"claim {self.id} has no model {label!r}; valid: {', '.join(m.label for m in self.models)}")

    def catalogue(self) -> dict:
        return {"id": self.id, "number": self.number, "paper": self.paper, "section": self.section,
                "title": self.title, "system": self.system, "models": [m.label for m in self.models],
                "metric": self.metric, "metric_label": self.metric_label, "published": self.published,
                "verdict_rule": self.verdict_rule,
                "protocol": {p: pr.to_dict() for p, pr in self.protocols.items()}}


def ratio_rule(better: str, worse: str, factor: float):
    """Reproduced if metric[better] * factor < metric[worse]; partly if merely smaller."""
    def rule(v):
        a, b = v.get(better), v.get(worse)
        if a is None or b is None:
            return "not run", f"missing {better if a is None else worse}"
        if a * factor < b:
            return "reproduced", f"{better} {a:.3g} < {worse} {b:.3g} / {factor:g}"
        if a < b:
            return "partly", f"{better} {a:.3g} < {worse} {b:.3g}, but not by {factor:g}x"
        return "not reproduced", f"{better} {a:.3g} >= {worse} {b:.3g}"
    return rule
