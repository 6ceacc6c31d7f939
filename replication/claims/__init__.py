"""The ten claims of the SPEC, by id, in the SPEC's order, then the hard-case claims (11: precision) and the
DeLaN paper's control experiments (12: delan_tracking; 13: delan_online, learning online).

`CLAIMS` holds each claim as it runs: its models with the protocols `lagbench tune` chose where a choice is
adopted (`tuned.py`); `untuned(id)` the claim as its file writes it, the base every tuning searches around."""
from lagbench.replication.claims import (
    activation_study,
    appendix_b,
    delan_arm,
    delan_online,
    delan_table1,
    delan_tracking,
    dp_energy,
    dp_loss,
    hnn_energy,
    init_study,
    precision,
    rel_coords,
    tuned,
    wave_lgn,
)
from lagbench.replication.claims.base import PROFILES, VERDICTS, Claim, ModelEntry

_ALL = (dp_loss, dp_energy, rel_coords, wave_lgn, appendix_b, init_study, activation_study, delan_table1,
        delan_arm, hnn_energy, precision, delan_tracking, delan_online)
_WRITTEN = {m.CLAIM.id: m.CLAIM for m in sorted(_ALL, key=lambda m: m.CLAIM.number)}
CLAIMS = {cid: tuned.apply(c) for cid, c in _WRITTEN.items()}


def get(claim_id: str) -> Claim:
    if claim_id not in CLAIMS:
        raise KeyError(f"unknown claim {claim_id!r}; valid: {', '.join(CLAIMS)}")
    return CLAIMS[claim_id]


def untuned(claim_id: str) -> Claim:
    get(claim_id)
    return _WRITTEN[claim_id]


__all__ = ["CLAIMS", "PROFILES", "VERDICTS", "Claim", "ModelEntry", "get", "untuned"]
