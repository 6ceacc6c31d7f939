"""What runs: `resolved(claim, profile)`, the one place where a claim as its file writes it becomes what a run
trains and evaluates under a profile.

A claim file writes its models, protocols, seeds and evaluation settings as literals (`base.Claim`); the
choices `lagbench tune` made are adopted in `tuned.json` (`tuned`), and only here are they applied: each
model that a search serves (`tuned.choice`) runs with the chosen knobs (`tuned.with_knobs`) under that profile.
Everything that needs what runs reads it here: the planner (`replication.run.runner.plan`), the registration
fingerprint (`registration.fingerprint`), the verdicts' record of how each model was tuned (`tuning`), the
run's claims catalogue (`catalogue`), the fit defaults and `lagbench list --claim ID --profile P`.

`resolved(claim, profile, adopted=None) -> Resolved`: per model that runs under the profile (`RunModel`): its
label, whether it trains, its ModelSpec fields, hidden widths and protocol, whether a search chooses its
settings and the adopted choice applied (`tuned.Adopted`; None: the registered, hand-chosen setting); the seed
count and the seeds of each split (`replication.run.splits`); the frameworks the profile decides in; the
evaluation config. `adopted`: tuned.json's records (default: the file's, `tuned.records()`). `describe()`: the
lines `lagbench list --claim ID --profile P` prints.
`tuning(claim, profile, adopted=None) -> {label: {...}}`: for verdicts.json and the report, per searched model
the configurations its protocol was chosen among and the split they were scored on (0 and None: by hand).
`catalogue(claim, profile, adopted=None) -> dict`: claims.json's record of a claim: the claim's catalogue and
what runs under the run's profile.
"""
from __future__ import annotations

from dataclasses import dataclass

from lagbench.replication.claims import tuned
from lagbench.replication.claims.base import ModelEntry, run_frameworks
from lagbench.replication.training.protocol import Protocol


@dataclass(frozen=True)
class RunModel:
    """One model as it runs under a profile."""

    label: str
    train: bool                  # False: evaluated without training
    spec: dict                   # ModelSpec fields (dof and dtype come from the system and the protocol)
    hidden: tuple                # hidden widths
    protocol: Protocol
    searched: bool               # whether `lagbench tune` chooses its rate and widths (`tuned.searched`)
    adopted: tuned.Adopted | None   # the adopted choice applied; None: the registered (hand-chosen) setting
    entry: ModelEntry            # the entry as it runs (a `replication.run.units.Unit` is made of it)

    def to_dict(self) -> dict:
        return {"train": self.train, "spec": dict(self.spec), "hidden": list(self.hidden),
                "protocol": self.protocol.to_dict(), "searched": self.searched,
                "adopted": self.adopted.describe() if self.adopted else None}


@dataclass(frozen=True)
class Resolved:
    """A claim under a profile as it runs."""

    claim: str
    profile: str
    models: tuple                # `RunModel`s, in the claim's order
    seeds: int                   # seeds a model
    seed_numbers: dict           # split name -> the seeds a run on that split trains
    frameworks: tuple            # the frameworks the profile trains and decides in
    eval: dict                   # the evaluation config

    @property
    def labels(self) -> list:
        return [m.label for m in self.models]

    def model(self, label: str) -> RunModel:
        for m in self.models:
            if m.label == label:
                return m
        raise KeyError(f"claim {self.claim} runs no model {label!r} under profile {self.profile}; valid: "
                       f"{', '.join(self.labels)}")

    def describe(self) -> list[str]:
        """Lines for `lagbench list --claim ID --profile P`: everything this record holds, per model its
        protocol's essentials."""
        seeds = "; ".join(f"{k} {', '.join(map(str, v))}" for k, v in self.seed_numbers.items())
        cfg = ", ".join(f"{k}={v}" for k, v in self.eval.items()) or "(the routine's defaults)"
        out = [f"seeds: {self.seeds} a model ({seeds})", f"frameworks: {', '.join(self.frameworks)}",
               f"evaluation config: {cfg}", "models:"]
        for m in self.models:
            a = m.adopted
            how = (f"tuned: lr x{a.knobs['lr']:.3g}, width x{a.knobs['width']:g} (tuned.json {a.claim}/{a.profile}/"
                   f"{a.label}, {a.configs_tried} configurations on {a.split}, ledger {a.ledger_hash})" if a
                   else "hand-chosen (no adopted search)" if m.searched else "hand-chosen (not searched)")
            out += [f"  {m.label}: {'trains' if m.train else 'no training'}; widths "
                    f"{'x'.join(map(str, m.hidden)) or '-'}; {how}",
                    "    spec: " + ", ".join(f"{k}={v}" for k, v in m.spec.items()),
                    "    protocol: " + _protocol_text(m.protocol)]
        return out

    def to_dict(self) -> dict:
        return {"claim": self.claim, "profile": self.profile, "seeds": self.seeds,
                "seed_numbers": {k: list(v) for k, v in self.seed_numbers.items()},
                "frameworks": list(self.frameworks), "eval": self.eval,
                "models": {m.label: m.to_dict() for m in self.models}}


def _schedule_text(schedule) -> str:
    from lagbench.replication.training.schedules import schedule_to_dict

    d = schedule_to_dict(schedule)
    return f"{d.pop('kind')} peak lr {d.pop('lr'):g}" + "".join(f", {k} {v:g}" for k, v in d.items())


def _protocol_text(p: Protocol) -> str:
    from lagbench.replication.training.scouting import budget_samples

    text = (f"{p.task}, loss {p.loss}, {p.dtype}; {p.steps} steps x batch {p.batch}, {_schedule_text(p.schedule)}; "
            f"data {p.data.recipe}: {p.data.n_train} train, {p.data.n_heldout} held-out"
            f"{' (resampled)' if p.data.resample else ''}")
    if p.scouting:
        s = p.scouting
        text += (f"; restarts {s.count} x {s.steps} steps x batch {s.batch}, {_schedule_text(s.schedule)}"
                 + (f", keep {s.keep}" if s.keep else ""))
    if p.guard:
        text += f"; guard clip {p.guard.clip:g} skip {p.guard.skip:g}"
    if p.cohort:
        text += f"; cohort {p.cohort}"
    return text + f"; {budget_samples(p):.3g} samples"


def resolved(claim, profile: str, adopted: dict | None = None) -> Resolved:
    from lagbench.replication.run import splits

    adopted = tuned.records() if adopted is None else adopted
    base = claim.protocol(profile)
    models = []
    for m in claim.models:
        if not m.runs_in(profile):
            continue
        searched = tuned.searched(claim, m, profile)
        choice = tuned.choice(claim, m, profile, adopted) if searched else None
        entry = tuned.with_knobs(m, base, profile, choice.knobs) if choice else m
        models.append(RunModel(label=m.label, train=m.train, spec=entry.spec_fields(profile),
                               hidden=entry.widths(profile), protocol=entry.protocol(base, profile),
                               searched=searched, adopted=choice, entry=entry))
    n = claim.n_seeds(profile)
    return Resolved(claim=claim.id, profile=profile, models=tuple(models), seeds=n,
                    seed_numbers={s.name: tuple(s.seeds(n)) for s in splits.SPLITS.values()},
                    frameworks=run_frameworks(profile), eval=claim.evaluation_config(profile))


_BY_HAND = {"configs_tried": 0, "scored_on": None, "knobs": None, "seeds": [], "confirm_seeds": [], "ledger_hash": None}


def tuning(claim, profile: str, adopted: dict | None = None) -> dict:
    out = {}
    for m in resolved(claim, profile, adopted).models:
        if not m.searched:
            continue
        a = m.adopted
        out[m.label] = ({"configs_tried": a.configs_tried, "scored_on": a.split, "knobs": dict(a.knobs),
                         "seeds": list(a.seeds), "confirm_seeds": list(a.confirm_seeds), "ledger_hash": a.ledger_hash,
                         **({"edge_limits": dict(a.edge_limits)} if a.edge_limits else {})}
                        if a else dict(_BY_HAND))
    return out


def catalogue(claim, profile: str, adopted: dict | None = None) -> dict:
    return {**claim.catalogue(), "runs": resolved(claim, profile, adopted).to_dict()}
