"""The registration and tuning of each claim's protocol, from verdicts.json's `preregistration`.

`registration_table(res)`: per claim, the hash of what decides it under the run's profile, the
registration line it matches, how its models were tuned (`tuning_text`) and its seed count's rule.
`tuning_table(res)`: per claim and trained model, the configurations its protocol was chosen among by
`lagbench tune`, the split they were scored on and the choice (knobs as multiples of the registered
setting); a model chosen among fewer configurations than a rival of its claim is flagged, and so is a search
whose edge step was bounded (`search.EDGE_LIMITS`).
`disclosed(res)`: the claims registered anew after a look at test-split numbers, with the note that says so.
`add_to(section, res)`: both tables, with their notes, and each disclosure in full; `summary(res)`: one
paragraph of both for the scorecard, naming the disclosed claims.
"""
from __future__ import annotations

import pandas as pd

from lagbench.replication.tuning.search import SIZE as SEARCH_SIZE
from lagbench.reports.document import Para, Section, Table
from lagbench.reports.fmt import cell
from lagbench.reports.load import Results


def _prereg(res: Results, claim: dict) -> dict:
    return (res.verdicts.get(claim["id"]) or {}).get("preregistration") or {}


def tuning_text(tuning: dict) -> str:
    if not tuning:
        return "no trained model"
    tried = {t["configs_tried"] for t in tuning.values()}
    if tried == {0}:
        return "by hand, no search"
    if len(tried) == 1:
        split = next(iter(tuning.values()))["scored_on"]
        return f"lagbench tune: {tried.pop()} configurations per model ({split})"
    return "UNEQUAL: " + ", ".join(f"{m} {t['configs_tried']}" for m, t in tuning.items())


def registration_table(res: Results) -> pd.DataFrame | None:
    rows = []
    profile = (res.run or {}).get("profile") or res.verdict_profile
    for claim in res.claims:
        r = _prereg(res, claim)
        if r:
            rows.append({"claim": claim["id"], "protocol hash": r["protocol_hash"],
                         "registered": f"yes, frozen {r['frozen']}" if r["registered"] else "NO: changed since",
                         "registrations": r["registrations"], "tuning": tuning_text(r.get("tuning") or {}),
                         "seeds (rule)": cell((claim.get("seed_rule") or {}).get(profile))})
    return pd.DataFrame(rows) if rows else None


def _knobs(k: dict | None) -> str:
    return "registered setting (by hand)" if not k else ", ".join(f"{n} x{v:.3g}" for n, v in k.items())


def _bounds(limits: dict) -> str:
    return ", ".join(f"{n} at most x{v:.3g}" for n, v in limits.items())


def tuning_table(res: Results) -> pd.DataFrame | None:
    rows = []
    for claim in res.claims:
        tuning = _prereg(res, claim).get("tuning") or {}
        most = max((t["configs_tried"] for t in tuning.values()), default=0)
        if not most:
            continue
        for model, t in tuning.items():
            confirmed = t.get("confirm_seeds") or []
            flags = ["LESS TUNING than a rival"] * (t["configs_tried"] < most)
            searched = t["configs_tried"] > 0   # 0: by hand
            flags += [f"partial search ({t['configs_tried']} of {SEARCH_SIZE})"] * (0 < t["configs_tried"] < SEARCH_SIZE)
            flags += ["unconfirmed: one seed"] * (searched and len(confirmed) < 2)
            if t.get("edge_limits"):
                flags.append(f"edge step bounded ({_bounds(t['edge_limits'])}, every model alike)")
            rows.append({"claim": claim["id"], "model": model, "configurations": t["configs_tried"],
                         "scored on": cell(t["scored_on"]), "dev seeds": ", ".join(map(str, t["seeds"])) or "-",
                         "confirmed on": ", ".join(map(str, confirmed)) or "-", "chosen": _knobs(t["knobs"]),
                         "flag": "; ".join(flags) or "none"})
    return pd.DataFrame(rows) if rows else None


def disclosed(res: Results) -> list[tuple[str, str]]:
    """(claim, note) of each claim whose matching registration was made after a look at test-split numbers:
    its note says so ("disclosed")."""
    return [(str(claim.get("number", claim["id"])), r["note"]) for claim in res.claims
            for r in [_prereg(res, claim)] if r.get("registered") and "disclosed" in (r.get("note") or "")]


def summary(res: Results) -> str:
    """How the claims' protocols were chosen and registered, in one paragraph (the tables are in the appendix)."""
    by = {}
    unregistered = []
    for claim in res.claims:
        r = _prereg(res, claim)
        if r:
            by.setdefault(tuning_text(r.get("tuning") or {}), []).append(str(claim.get("number", claim["id"])))
            if not r["registered"]:
                unregistered.append(claim["id"])
    if not by:
        return "Protocols: no registration is recorded for this run."
    text = "; ".join(f"claim{'s' if len(ns) > 1 else ''} {', '.join(ns)}: {how}" for how, ns in by.items())
    return (f"How each claim's protocol was chosen: {text}. "
            + (f"NOT REGISTERED (changed since their registration): {', '.join(unregistered)}. " if unregistered
               else "Every protocol matches its registration. ")
            + (f"Registered anew after a look at test-split numbers, disclosed: claim"
               f"{'s' if len(disclosed(res)) > 1 else ''} {', '.join(c for c, _ in disclosed(res))}. "
               if disclosed(res) else "")
            + "The registrations, the tuning ledger and the seed rule per claim: appendix, 'Parts, reasons and "
              "registrations'.")


def add_to(s: Section, res: Results) -> None:
    registered = registration_table(res)
    if registered is not None:
        s.add(Table("Registered protocols", registered, ["replication/claims/registrations.json",
                                                         "replication/claims/tuned.json"],
                    note="What decides each claim under this profile (its models' specs and protocols, the "
                         "evaluation, the seeds, the bars and the rules) is hashed and registered before a "
                         "test-split run; a change after one is a new dated registration, never a silent edit. "
                         "'tuning' says how the models' protocols were chosen: by `lagbench tune` (the same "
                         "configurations for every model, scored on the development split) or by hand."))
    by_note: dict = {}
    for claim, note in disclosed(res):
        by_note.setdefault(note, []).append(claim)
    for note, claims in by_note.items():
        s.add(Para(f"Claim{'s' if len(claims) > 1 else ''} {', '.join(claims)}: registered anew after a look at "
                   f"test-split numbers (disclosed): {note.rstrip('.')}."))
    ledger = tuning_table(res)
    if ledger is not None:
        s.add(Table("Tuning ledger", ledger, ["replication/claims/tuned.json", "docs/lab/search/*/ledger.json"],
                    note="Per model of a tuned claim: how many configurations of the declared search (peak rate "
                         f"x 1/3, 1, 3 by hidden widths x 1/2, 1, 2: {SEARCH_SIZE}, the registered setting among them, "
                         "one step further where a model's best lies on an edge) it was chosen among, on which "
                         "split and seeds, the development seeds its choice was confirmed on against the "
                         "registered setting, and the choice as multiples of the registered setting. A partial "
                         "search (fewer configurations) or an unconfirmed choice is flagged. Claims not listed "
                         "were tuned by hand."))
