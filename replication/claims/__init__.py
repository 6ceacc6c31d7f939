"""The claims, discovered: every module of this package whose top level writes `CLAIM = Claim(...)`, by id, in
the order of their numbers (the SPEC's ten claims, then the hard-case check 11, precision, and the DeLaN
paper's control experiments 12 and 13).

`CLAIMS` and `get(id)` hold each claim as its file writes it. What runs under a profile (the protocols
`lagbench tune` chose applied where a choice is adopted) is `resolved.resolved(claim, profile)`.
`discover(name, path) -> {id: Claim}`: the claims of a package's modules (a new claim file needs no listing).
"""
import importlib
import pkgutil
import re
from pathlib import Path

from lagbench.replication.claims.base import PROFILES, VERDICTS, Claim, ModelEntry

_WRITES_A_CLAIM = re.compile(r"^CLAIM\s*=\s*Claim\(", re.MULTILINE)


def _writes_a_claim(path: str, name: str) -> bool:
    source = Path(path, f"{name}.py")
    return source.is_file() and bool(_WRITES_A_CLAIM.search(source.read_text(encoding="utf-8")))


def discover(name: str, path) -> dict:
    """{id: Claim} of the modules of the package `name` (its `__path__`: `path`) whose top level assigns
    `CLAIM = Claim(...)`, ordered by claim number; a module only of shared settings or machinery is not
    imported here."""
    found = []
    for info in pkgutil.iter_modules(path):
        if info.ispkg or not _writes_a_claim(info.module_finder.path, info.name):
            continue
        claim = importlib.import_module(f"{name}.{info.name}").CLAIM
        if not isinstance(claim, Claim):
            raise TypeError(f"{name}.{info.name}.CLAIM is a {type(claim).__name__}, not a Claim")
        found.append(claim)
    numbers = [c.number for c in found]
    ids = [c.id for c in found]
    for what, values in (("number", numbers), ("id", ids)):
        twice = sorted({v for v in values if values.count(v) > 1})
        if twice:
            raise ValueError(f"claims share a {what}: {', '.join(map(str, twice))}")
    return {c.id: c for c in sorted(found, key=lambda c: c.number)}


CLAIMS = discover(__name__, __path__)


def get(claim_id: str) -> Claim:
    if claim_id not in CLAIMS:
        raise KeyError(f"unknown claim {claim_id!r}; valid: {', '.join(CLAIMS)}")
    return CLAIMS[claim_id]


__all__ = ["CLAIMS", "PROFILES", "VERDICTS", "Claim", "ModelEntry", "discover", "get"]
