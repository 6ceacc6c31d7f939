"""A claim's parts, its sanity checks and its variants, and the fixed function from parts to a verdict.

- ``Part``: one named, separately decidable statement of a claim (claim 4: "transfer to 100 points",
  "energy conservation"), decided per framework by its rule (``rules``) on the models it ``reads``.
  Each model it reads must pass its competence bar; each of its ``controls`` (positive controls: the
  same pipeline must show that a model the part says fails can succeed where the paper says it should)
  must pass its bar too, else the part is "inconclusive". ``check=True`` marks a sanity check (a statement
  a null model also passes, or one that holds by construction): shown, never counted in the verdict.
- ``Budget``: for a part that says a paper model learns, what the original needed: the model (``model``), its
  widths and the samples after which it had learned. Such a part reads "not reproduced" (the model does not
  learn) only when every condition of ``Budget.decides`` holds: the paper's widths, at least the original's
  samples, at least ``Budget.MIN_SEEDS`` seeds, every seed below its bar, and the part's positive controls
  passing in the same pipeline. Short of that it reads "inconclusive: budget (x % of the original's
  samples)", or "inconclusive: pipeline" where a control failed.
- ``Variant``: a model with a departure from the paper (an extra input, another target) standing in for
  the paper's model: the claim is judged again with the variant's units in the paper model's place, and
  that verdict is the variant's own line. It never decides the claim.
- ``claim_verdict(part verdicts)``: the claim's verdict from its (non-check) parts, the same function for
  every claim: "not run" if no part ran; "inconclusive" if any part is inconclusive or not run; else
  "reproduced" if every part is, "not reproduced" if none is, and otherwise "partly", which then means
  only "these named parts reproduced, those did not".
- ``combine_frameworks(verdicts)``: one part's verdict over frameworks: equal verdicts stand; decided
  verdicts that differ are "inconclusive" and flagged as a defect (two frameworks that start from the
  same weights and batches must agree); any other mix (one undecided) is "inconclusive".
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

DISAGREE = "frameworks disagree"


@dataclass(frozen=True)
class Budget:
    model: str               # the paper model the part says learns
    width: tuple             # the original's hidden widths
    samples: float           # the training samples after which the original had learned
    source: str              # where that is recorded
    MIN_SEEDS = 5            # the fewest seeds a "does not learn" rests on

    def describe(self) -> dict:
        return {"model": self.model, "width": list(self.width), "samples": self.samples, "source": self.source}

    def shortfall(self, width: tuple, samples: float, seeds: int) -> list[str]:
        """What keeps a failure to learn from deciding: [] when the paper's model had the original's chance."""
        out = []
        if tuple(width) != tuple(self.width):
            out.append(f"width {'x'.join(map(str, width)) or 'unknown'}, the original's "
                       f"{'x'.join(map(str, self.width))}")
        if not samples >= self.samples:
            out.append(f"budget {100 * samples / self.samples:.3g} % of the original's {self.samples:.3g} samples")
        if seeds < self.MIN_SEEDS:
            out.append(f"{seeds} seeds (at least {self.MIN_SEEDS})")
        return out


@dataclass(frozen=True)
class Part:
    name: str
    rule: Callable           # {label: {metric: Stat}} -> rules.Outcome
    reads: tuple             # the model labels the rule reads; each must pass its bars
    controls: tuple = ()     # positive controls: labels that must pass their bars for the part to be decided
    check: bool = False      # a sanity check, not a part: never counted in the claim's verdict
    budget: Budget | None = None   # for a part that says a model learns: what the original needed

    def describe(self) -> dict:
        return {"name": self.name, "reads": list(self.reads), "controls": list(self.controls), "check": self.check,
                **({"budget": self.budget.describe()} if self.budget else {})}

    def runs_in(self, labels) -> bool:
        """Whether every model the part reads or controls runs (a part of pools a profile does not train
        is not a part of that profile's verdict)."""
        return set(self.reads) | set(self.controls) <= set(labels)


@dataclass(frozen=True)
class Variant:
    name: str                # the variant's line, e.g. "LNN with gamma(qdot) input"
    replaces: tuple          # ((paper model label, variant model label), ...)
    departure: str           # what differs from the paper

    def describe(self) -> dict:
        return {"name": self.name, "replaces": dict(self.replaces), "departure": self.departure}


def claim_verdict(verdicts: dict) -> tuple[str, str]:
    """(verdict, reason) of a claim from {part name: verdict} of its counted parts."""
    if not verdicts or all(x == "not run" for x in verdicts.values()):
        return "not run", "no part ran"

    def names(*which):
        return ", ".join(k for k, x in verdicts.items() if x in which)
    if any(x in ("inconclusive", "not run") for x in verdicts.values()):
        return "inconclusive", f"undecided: {names('inconclusive', 'not run')}"
    if all(x == "reproduced" for x in verdicts.values()):
        return "reproduced", "every part reproduced"
    if all(x == "not reproduced" for x in verdicts.values()):
        return "not reproduced", "no part reproduced"
    return "partly", f"reproduced: {names('reproduced')}; not reproduced: {names('not reproduced')}"


def combine_frameworks(by_fw: dict) -> tuple[str, str]:
    """(verdict, flag) of one part over its frameworks' verdicts; flag is DISAGREE or ""."""
    run = set(by_fw.values())
    if not run:
        return "not run", ""
    if len(run) == 1:
        return run.pop(), ""
    decided = run & {"reproduced", "not reproduced"}
    if len(decided) > 1:
        return "inconclusive", DISAGREE
    return ("not run", "") if run == {"not run"} else ("inconclusive", "")
