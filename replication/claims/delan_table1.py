"""Claim 8 (LNN Table 1): DeLaN cannot model a Lagrangian whose kinetic part is not quadratic in
qdot (the relativistic particle, here at a fixed field g = 9.8) or has a part linear in qdot (the
charged particle in a magnetic field); the LNN can."""
from replication.claims.base import Claim, ModelEntry
from replication.protocol import Protocol

W = {"smoke": (16, 16), "quick": (128, 128), "paper": (256, 256, 256)}
REL = {"data": "relativistic_iid", "system_params": (("g", 9.8),)}
MAG = {"data": "charged_magnetic_iid"}
_delan = {"kind": "delan", "activation": "softplus", "init": "xavier"}
_lnn = {"kind": "lnn", "activation": "softplus", "init": "cranmer2020"}
MODELS = (ModelEntry("delan_relativistic", _delan, hidden=W, overrides=REL),
          ModelEntry("lnn_relativistic", _lnn, hidden=W, overrides=REL),
          ModelEntry("delan_magnetic", _delan, hidden=W, overrides=MAG),
          ModelEntry("lnn_magnetic", _lnn, hidden=W, overrides=MAG))
_base = Protocol(data="charged_magnetic_iid", steps=20, batch=32, n_train=640, n_heldout=512, loss="l1",
                 lr=1e-3, schedule="onecycle", log_every=5)
PROTOCOLS = {"smoke": _base,
             "quick": _base.replace(steps=1500, batch=256, n_train=256 * 200, n_heldout=10_000, log_every=50),
             "paper": _base.replace(steps=100_000, batch=512, n_train=512 * 1000, n_heldout=100_000, log_every=1000)}


def _verdict(v):
    out = []
    for sysname in ("relativistic", "magnetic"):
        d, lnn = v.get(f"delan_{sysname}"), v.get(f"lnn_{sysname}")
        if d is None or lnn is None:
            return "not run", f"missing {sysname}"
        out.append((sysname, lnn * 3 < d, lnn < d, f"{sysname}: lnn {lnn:.3g} vs delan {d:.3g}"))
    reason = "; ".join(o[3] for o in out)
    if all(o[1] for o in out):
        return "reproduced", reason
    if any(o[2] for o in out):
        return "partly", reason
    return "not reproduced", reason


CLAIM = Claim(
    id="delan_table1", number=8, paper="LNN", section="Table 1",
    title="DeLaN cannot model non-quadratic or velocity-linear kinetic terms; the LNN can",
    system="relativistic, charged_magnetic", models=MODELS, protocols=PROTOCOLS, evaluate="heldout",
    metric="heldout_l1", metric_label="held-out per-sample L1 of q-double-dot",
    published={m.label: None for m in MODELS},
    verdict_rule="lnn * 3 < delan on both systems (partly: on one)", verdict=_verdict,
    seeds={"smoke": 1, "quick": 2, "paper": 3},
)
