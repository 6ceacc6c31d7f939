"""The declarative claim record.

A `Claim` names a paper result and everything needed to check it: the system, the models (each a
`ModelEntry`: a label, ModelSpec fields, protocol overrides), the protocol per profile, the
evaluation routine (a name in `replication.evaluation.registry.EVALUATIONS`), the metric the verdict reads,
the published values (`published.Published`, each with what it is), the competence bars its models
must pass (`bars.Bar`), its parts (`parts.Part`: each a rule from `rules`, the models it reads and its
positive controls; sanity checks among them marked as such) and its variants (`parts.Variant`: models
with a departure from the paper, judged on their own line). ``kind`` is "claim" for a paper claim and
"check" for an implementation or numerics check, reported apart and not counted among the claims.
A claim is written as literals and read as written; what runs under a profile, the adopted tuning applied, is
`replication.claims.resolved.resolved(claim, profile)`. Where a verdict is decided:
`replication.claims.verdicts.judge`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from lagbench.replication.claims import seed_rule
from lagbench.replication.claims.parts import Part, Variant
from lagbench.replication.claims.rules import VERDICTS
from lagbench.replication.training.protocol import Protocol

PROFILES = ("smoke", "quick", "full", "paper")
# no profile inherits another's settings (`per_profile`): every per-profile table of a claim names each profile
# it serves, and a `full` that runs quick's settings names quick's values under "full"
KINDS = ("claim", "check")
FRAMEWORKS = ("jax", "torch")
# the frameworks a profile trains and decides in when a run names none: `quick`, the preliminary profile, in
# JAX alone (training both frameworks would double its time; the tests hold PyTorch's steps equal to JAX's on
# identical weights and batches); the profiles of record in both, a claim's parts decided in each
PROFILE_FRAMEWORKS = {"smoke": FRAMEWORKS, "quick": ("jax",), "full": FRAMEWORKS, "paper": FRAMEWORKS}


def run_frameworks(profile: str, frameworks=None) -> tuple:
    """The frameworks a run trains in: those named, else the profile's (both for a profile not listed)."""
    return tuple(frameworks) if frameworks is not None else PROFILE_FRAMEWORKS.get(profile, FRAMEWORKS)


__all__ = ["PROFILES", "FRAMEWORKS", "PROFILE_FRAMEWORKS", "run_frameworks", "VERDICTS", "KINDS", "Claim", "ModelEntry", "Part", "Variant", "per_profile"]


def per_profile(table: dict, profile: str, default=None):
    """`table[profile]`, else `default`: every profile a table serves is spelled out in it (no inheritance)."""
    return table.get(profile, default)


def in_profile(profiles: tuple, profile: str) -> bool:
    """Whether a model limited to `profiles` runs in `profile`."""
    return profile in profiles


@dataclass(frozen=True)
class ModelEntry:
    """One model of a claim. `spec` holds ModelSpec fields except dof and dtype (taken from the system
    and the protocol); `hidden` may map a profile to widths; `overrides` change the claim's protocol
    for this model (another data recipe, task, loss, learning rate, pool size...), optionally per
    profile as {profile: {...}}; `profile_spec` adds ModelSpec fields in one profile only, as
    {profile: {field: value}}; `train=False` marks a model evaluated without training; `profiles` limits
    the profiles the model runs in; `tuned_as` names the model whose adopted tuning it takes (a positive
    control: the same model on other data, tuned exactly as the model it vouches for)."""

    label: str
    spec: dict
    hidden: dict | tuple = ()
    overrides: dict = field(default_factory=dict)
    train: bool = True
    profiles: tuple = PROFILES   # the profiles this model runs in
    profile_spec: dict = field(default_factory=dict)
    tuned_as: str = ""

    def spec_fields(self, profile: str) -> dict:
        return {**self.spec, **per_profile(self.profile_spec, profile, {})}

    def widths(self, profile: str) -> tuple:
        h = per_profile(self.hidden, profile, ()) if isinstance(self.hidden, dict) else self.hidden
        return tuple(h)

    def runs_in(self, profile: str) -> bool:
        return in_profile(self.profiles, profile)

    def protocol(self, base: Protocol, profile: str) -> Protocol:
        common = {k: v for k, v in self.overrides.items() if k not in PROFILES}
        per = per_profile({k: v for k, v in self.overrides.items() if k in PROFILES}, profile, {})
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
    published: dict          # model label -> Published (only numbers a paper or its repository prints)
    verdict_rule: str
    parts: tuple             # `parts.Part`s: the claim's verdict is `parts.claim_verdict` of the counted ones
                             # (none: a fit of a user's data, which has no verdict)
    bars: tuple = ()         # competence bars (`bars.Bar`); a model below its bar -> its parts "inconclusive"
    variants: tuple = ()     # `parts.Variant`s: departures from the paper, each judged on its own line
    kind: str = "claim"      # "claim" (a paper claim) or "check" (implementation, numerics)
    key: str = ""            # the model whose number the scorecard shows (default: the first)
    # seeds a model per profile; the default is the seed rule's count (`seed_rule`) in every profile
    seeds: dict = field(default_factory=lambda: {"smoke": 1, "quick": seed_rule.PRELIMINARY_SEEDS,
                                                 "full": seed_rule.RECORD_SEEDS, "paper": seed_rule.RECORD_SEEDS})
    eval_config: dict = field(default_factory=dict)   # profile -> dict of evaluation settings
    pooled: bool = False     # the rule reads the seeds as one sample (a share), not each seed as a replication

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"claim {self.id}: kind must be one of {KINDS}, got {self.kind!r}")
        labels = {m.label for m in self.models}
        named = {x for p in self.parts for x in (*p.reads, *p.controls)}
        named |= {x for v in self.variants for pair in v.replaces for x in pair}
        if named - labels:
            raise ValueError(f"claim {self.id}: parts or variants name unknown models {sorted(named - labels)}")
        if self.parts and not any(not p.check for p in self.parts):   # no parts: a fit of user data, no verdict
            raise ValueError(f"claim {self.id}: no part that counts (every part is a check)")

    def entry(self, label: str) -> ModelEntry:
        for m in self.models:
            if m.label == label:
                return m
        raise KeyError(f"claim {self.id} has no model {label!r}; valid: {', '.join(m.label for m in self.models)}")

    def catalogue(self) -> dict:
        return {"id": self.id, "number": self.number, "paper": self.paper, "section": self.section,
                "title": self.title, "system": self.system, "models": [m.label for m in self.models],
                "metric": self.metric, "metric_label": self.metric_label,
                "published": {k: p.to_dict() for k, p in self.published.items()},
                "kind": self.kind, "verdict_rule": self.verdict_rule, "bars": [b.describe() for b in self.bars],
                "parts": [p.describe() for p in self.parts], "variants": [v.describe() for v in self.variants],
                "key": self.key_model, "seeds": dict(self.seeds), "pooled": self.pooled,
                "seed_rule": {p: seed_rule.describe(self, p) for p in PROFILES},
                "protocol": {p: pr.to_dict() for p, pr in self.protocols.items()}}

    def controls(self) -> list:
        """The positive controls (models a part controls and none reads), in the claim's model order."""
        controlling = {x for p in self.parts for x in p.controls} - {x for p in self.parts for x in p.reads}
        return [m.label for m in self.models if m.label in controlling]

    def variant_models(self) -> list:
        """The variants' models (`parts.Variant`: each stands in for a paper model), in the claim's model order."""
        standing_in = {v for var in self.variants for _, v in var.replaces}
        return [m.label for m in self.models if m.label in standing_in]

    def paper_models(self) -> list:
        """The models the claim is decided on: neither a positive control nor a variant's."""
        other = {*self.controls(), *self.variant_models()}
        return [m.label for m in self.models if m.label not in other]

    def paper_model(self, label: str) -> str:
        """The paper model a variant's model stands in for; any other model's own label."""
        return {v: p for var in self.variants for p, v in var.replaces}.get(label, label)

    @property
    def key_model(self) -> str:
        return self.key or self.models[0].label

    def labels(self, profile: str | None = None) -> list:
        """The model labels that run in ``profile`` (all of them if None)."""
        return [m.label for m in self.models if profile is None or m.runs_in(profile)]

    def protocol(self, profile: str) -> Protocol:
        """The claim's protocol under `profile` (before any model's overrides)."""
        p = per_profile(self.protocols, profile)
        if p is None:
            raise KeyError(f"claim {self.id} has no protocol for profile {profile!r}")
        return p

    def n_seeds(self, profile: str) -> int:
        return per_profile(self.seeds, profile, 1)

    def evaluation_config(self, profile: str) -> dict:
        return per_profile(self.eval_config, profile, {})
