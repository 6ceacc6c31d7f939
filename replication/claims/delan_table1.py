"""Claim 8 (LNN Table 1): DeLaN cannot model a Lagrangian whose kinetic part is not quadratic in
qdot (the relativistic particle, here at a fixed field g = 9.8) or has a part linear in qdot (the
charged particle in a magnetic field); the LNN can.

Decided on the paper's models: the LNN on (q, qdot). DeLaN's failure counts only beside its positive
control: the same DeLaN, protocol and pipeline on the pendulum (kinetic energy quadratic in qdot), where
its form holds, must pass the bar. The control cannot be on the claim's own systems: on the relativistic
particle at the claim's fixed field, DeLaN's form gives a constant q-double-dot even at low speed (the
potential is linear in q, so its best is the null predictor's mean), and the charged particle without its
field is a free particle (q-double-dot zero, the null's own answer); neither can pass a bar relative to the
null. Claim 3's controls are on its particle, which draws the field per sample. A variant beside the claim feeds the relativistic LNN the Lorentz
factor gamma(qdot) as well (`ModelSpec.lorentz_factor`, scaled by 0.01; claim 3 says why); it has its
own verdict line and never decides. DeLaN's kinetic energy is quadratic in qdot by construction, whatever
its inputs: it gets no such feature.
"""
from lagbench.replication.claims.bars import Bar
from lagbench.replication.claims.base import Claim, ModelEntry, Part, Variant
from lagbench.replication.claims.rules import better_by
from lagbench.replication.claims.seed_rule import PRELIMINARY_SEEDS
from lagbench.replication.training.protocol import Data, Protocol, Scouting
from lagbench.replication.training.schedules import OneCycle

W = {"smoke": (16, 16), "quick": (128, 128), "full": (128, 128), "paper": (256, 256, 256)}
# quick: the relativistic models (all alike) with restarts over initialisations, 8 scouts x 200 steps, the
# best by training loss continued. The magnetic pair and DeLaN's control train without.
_SCOUTS = Scouting(count=8, steps=200, batch=256, schedule=OneCycle(lr=1e-3, start=0.2))   # at quick's batch, rate and start
# the relativistic models sample as claim 3's (the original's): velocities drawn once, q redrawn every epoch
REL = {"data.recipe": "relativistic_iid", "data.system_params": (("g", 9.8),), "data.resample": True,
       "data.fixed": ("qdot",), "quick": {"scouting": _SCOUTS}, "full": {"scouting": _SCOUTS}}
MAG = {"data.recipe": "charged_magnetic_iid"}
_delan = {"kind": "delan", "activation": "softplus", "init": "xavier"}
_lnn = {"kind": "lnn", "activation": "softplus", "init": "cranmer2020"}
# the relativistic LNNs as claim 3's (the original's): q / 10 at the input, q-derivatives in the scaled q
_REL_LNN = {**_lnn, "input_scale": (0.1, 1.0), "scale_q_before_grad": True}
CONTROL = {"data.recipe": "pendulum_iid"}   # kinetic energy q-dot^2 / 2: DeLaN's form holds
MODELS = (ModelEntry("delan_relativistic", _delan, hidden=W, overrides=REL),
          ModelEntry("lnn_relativistic", _REL_LNN, hidden=W, overrides=REL),
          ModelEntry("lnn_relativistic_gamma", {**_REL_LNN, "lorentz_factor": True, "input_scale": (0.1, 1.0, 0.01)},
                     hidden=W, overrides=REL),
          ModelEntry("delan_magnetic", _delan, hidden=W, overrides=MAG),
          ModelEntry("lnn_magnetic", _lnn, hidden=W, overrides=MAG),
          ModelEntry("delan_control", _delan, hidden=W, overrides=CONTROL))
_data = Data("charged_magnetic_iid", n_train=640, n_heldout=512)
_base = Protocol(data=_data, steps=20, batch=32, loss="l1", schedule=OneCycle(lr=1e-3), log_every=5)
QUICK = _base.replace(steps=1500, batch=256, data=_data.replace(n_train=256 * 200, n_heldout=10_000), log_every=50)
PROTOCOLS = {"smoke": _base, "quick": QUICK, "full": QUICK,   # full runs quick's protocol
             "paper": _base.replace(steps=100_000, batch=512, data=_data.replace(n_train=512 * 1000, n_heldout=100_000),
                                    log_every=1000)}


CLAIM = Claim(
    id="delan_table1", number=8, paper="LNN", section="Table 1",
    title="DeLaN cannot model non-quadratic or velocity-linear kinetic terms; the LNN can",
    system="relativistic, charged_magnetic", models=MODELS, protocols=PROTOCOLS, evaluate="heldout",
    metric="heldout_l1", metric_label="held-out per-sample L1 of q-double-dot",
    published={},
    verdict_rule="lnn / delan < 1/3 over the 90 % interval of the seeds, on each system (a part each), with DeLaN's positive "
                 "control (the pendulum) past its bar",
    parts=tuple(Part(s, better_by(f"lnn_{s}", f"delan_{s}", 3.0, "heldout_l1"), reads=(f"lnn_{s}", f"delan_{s}"),
                     controls=("delan_control",)) for s in ("relativistic", "magnetic")),
    variants=(Variant("relativistic LNN also fed gamma(qdot)", (("lnn_relativistic", "lnn_relativistic_gamma"),),
                      "the LNN sees the Lorentz factor gamma(qdot) x 0.01 as an extra input; the paper's sees qdot "
                      "alone"),),
    # the claim is that the LNN can: it must have learned; DeLaN is expected not to, and its control must learn
    bars=(Bar(("lnn_relativistic", "lnn_relativistic_gamma", "lnn_magnetic", "delan_control"), "heldout_l1"),),
    key="lnn_relativistic", seeds={"smoke": 1, "quick": PRELIMINARY_SEEDS, "full": 5, "paper": 5},
)
