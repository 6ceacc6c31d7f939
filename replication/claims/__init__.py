"""The ten claims of the SPEC, by id, in the SPEC's order, then the hard-case claims (11: precision)."""
from replication.claims import (
    activation_study,
    appendix_b,
    delan_arm,
    delan_table1,
    dp_energy,
    dp_loss,
    hnn_energy,
    init_study,
    precision,
    rel_coords,
    wave_lgn,
)
from replication.claims.base import PROFILES, VERDICTS, Claim, ModelEntry

_ALL = (dp_loss, dp_energy, rel_coords, wave_lgn, appendix_b, init_study, activation_study, delan_table1,
        delan_arm, hnn_energy, precision)
CLAIMS = {m.CLAIM.id: m.CLAIM for m in sorted(_ALL, key=lambda m: m.CLAIM.number)}


def get(claim_id: str) -> Claim:
    if claim_id not in CLAIMS:
        raise KeyError(f"unknown claim {claim_id!r}; valid: {', '.join(CLAIMS)}")
    return CLAIMS[claim_id]


__all__ = ["CLAIMS", "PROFILES", "VERDICTS", "Claim", "ModelEntry", "get"]
