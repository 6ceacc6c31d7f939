"""The double pendulum's shared settings (LNN §5): named records that claims include by name. Shared settings,
not a claim; an edit to a record changes every claim that includes it (and so re-registers each).

  MODELS          the LNN and the baseline                   claims 1, 2 (one training), 11 (per dtype); speed study
  WIDTHS          their hidden widths per profile            MODELS; 11; claims 6-7 (`pace_study`, at quick's)
  VELOCITY_SCALE  velocity inputs x 0.3 (quick, full)        MODELS; claims 6-7
  RESTARTS        restarts + spike guard, 1.1e7 samples      quick of claims 1-2; full of 11; claims 6-7's scouts;
                                                             the speed study's members
  PROTOCOLS       per profile: SMOKE, RESTARTS, FULL, PAPER  claims 1, 2; 11 (smoke, paper); claims 6-7 (smoke, paper)
  PLAIN_QUICK     a short LNN protocol without restarts      the speed study (`speedstudy.learned`, train-to-target)
  SEEDS, LEARNED  seeds per profile; both models' bar        claims 1, 2
  EVAL            energy rollouts per profile                claims 2, 11
  ORIGINAL        the original's widths and samples          claims 1, 2 (published values)

Every number's origin (the original code's protocol, reference §2-§3, and the measurements behind each
departure): `docs/decisions/double_pendulum_protocol.md`. What runs under a profile, the adopted tuning
applied: `lagbench list --claim dp_loss --profile quick`.
"""
from lagbench.replication.claims.bars import Bar
from lagbench.replication.claims.base import ModelEntry
from lagbench.replication.claims.seed_rule import PRELIMINARY_SEEDS
from lagbench.replication.training.protocol import Data, Guard, Protocol, Scouting, Tracking
from lagbench.replication.training.schedules import OneCycle, StepDecay
from lagbench.replication.training.scouting import scouting_samples

PAPER_W, QUICK_W, SMOKE_W = (600, 600, 600), (64, 64, 64), (16, 16)
FULL_W = (128, 128, 128)
WIDTHS = {"smoke": SMOKE_W, "quick": QUICK_W, "full": FULL_W, "paper": PAPER_W}

# the MLP's inputs (angles wrapped to [-pi, pi), velocities U[-10, 10]) with the velocities x 0.3
VELOCITY_SCALE = {"smoke": {"input_scale": (1.0, 1.0, 0.3, 0.3)}, "quick": {"input_scale": (1.0, 1.0, 0.3, 0.3)},
                  "full": {"input_scale": (1.0, 1.0, 0.3, 0.3)}, "paper": {}}

MODELS = (
    ModelEntry("lnn", {"kind": "lnn", "activation": "softplus", "init": "cranmer2020", "angle_wrap": True,
                       "formulation": "fast"},
               hidden=WIDTHS, profile_spec=VELOCITY_SCALE),
    ModelEntry("baseline", {"kind": "baseline", "activation": "relu", "init": "xavier", "angle_wrap": True},
               hidden=WIDTHS, profile_spec=VELOCITY_SCALE),
)

# the original code's data and optimisation: i.i.d. states resampled every epoch, per-sample L1, l2 1e-6/512,
# Adam with the one-cycle at peak 1e-3
_data = Data("double_pendulum_iid", n_train=640, n_heldout=512, resample=True)
_base = Protocol(data=_data, steps=20, batch=32, loss="l1", l2=1e-6 / 512, schedule=OneCycle(lr=1e-3), log_every=5)

# the speed study's short LNN protocol: a constant 3e-3, then one decay, 4000 steps at batch 128
PLAIN_QUICK = _base.replace(steps=4000, batch=128, data=_data.replace(n_train=128 * 1000, n_heldout=20_000), log_every=50,
                            schedule=StepDecay(lr=3e-3, every=2500, gamma=0.1))

GUARD = Guard(clip=100.0, skip=10.0)   # the gradient-spike guard
# 16 scouts (batch 32, peak 1e-3, one-cycle of 15 625 steps from phase 0.2), the best 4 at its half kept to its
# end; the best continued at batch 256 for 6e6 samples (one-cycle at peak 1e-2 from phase 0.1, fresh Adam), and
# where that continuation ends above its scout's training loss, the next scout's, up to 3 more (`fallback`);
# 1.1e7 samples in all; the held-out loss tracked with its checkpoints kept (claim 2 reads matched accuracy)
RESTARTS = _base.replace(steps=6_000_000 // 256, batch=256, data=_data.replace(n_train=256 * 1000, n_heldout=20_000),
                         log_every=250, schedule=OneCycle(lr=1e-2, start=0.1),
                         scouting=Scouting(count=16, steps=15_625, batch=32, schedule=OneCycle(lr=1e-3, start=0.2), keep=4,
                                           fallback=3),
                         tracking=Tracking(every=1000, keep=True), guard=GUARD)
SMOKE = _base.replace(scouting=Scouting(count=2, steps=10, batch=16, schedule=OneCycle(lr=1e-3, start=0.2)),
                      tracking=Tracking(every=5, keep=True), guard=GUARD)
# the original code's budget: 300 epochs x 2000 batches of 512 from scratch, judged on 1e5 held-out states
PAPER = _base.replace(steps=600_000, batch=512, data=_data.replace(n_train=512 * 2000, n_heldout=100_000),
                      log_every=2000)
# RESTARTS with the continuation at peak 2e-3 from phase 0.2, for 4e7 samples in all, judged on 1e5 held-out states
FULL_SAMPLES = 40_000_000
_full = RESTARTS.replace(data=RESTARTS.data.replace(n_heldout=100_000),
                         schedule=OneCycle(lr=2e-3, start=0.2), log_every=1000, tracking=Tracking(every=5000, keep=True))
FULL = _full.replace(steps=(FULL_SAMPLES - scouting_samples(_full)) // _full.batch)
PROTOCOLS = {"smoke": SMOKE, "quick": RESTARTS, "full": FULL, "paper": PAPER}


def unkept(protocol):
    """The protocol without kept checkpoints (claims that train other models on it need none)."""
    return protocol.replace(**{"tracking.keep": False}) if protocol.tracking else protocol


# seeds by `seed_rule`: PRELIMINARY_SEEDS in the preliminary quick profile, 5 in the profiles of record
SEEDS = {"smoke": 1, "quick": PRELIMINARY_SEEDS, "full": 5, "paper": 5}

# both models must have learned q-double-dot on the training distribution before they are compared
LEARNED = Bar(("lnn", "baseline"), "heldout_l1")

# the original's double-pendulum models as published: 3 x 600, and the logged stage of their training (300
# epochs x 2000 minibatches x 512; a continuation of earlier training, so at least that)
ORIGINAL = {"width": PAPER_W, "samples": 300 * 2000 * 512}

# the original code's energy scale: m1 g l1 + m2 g (l1 + l2) = 29.4 ("max potential energy", m = l = 1)
ENERGY_SCALE = 29.4

# energy evaluation: initial conditions released near rest (velocities U[0, 0.1)), rolled out to T: every
# profile that decides claim 2 at the paper's 40 initial conditions to t = 100 (the original code's cell 48);
# smoke on a short horizon
PAPER_HORIZON = {"n_ics": 40, "t_end": 100.0, "n_t": 1000, "dt": 0.01, "energy_scale": ENERGY_SCALE}
EVAL = {"smoke": {"n_ics": 3, "t_end": 2.0, "n_t": 21, "dt": 0.01, "energy_scale": ENERGY_SCALE},
        "quick": PAPER_HORIZON, "full": PAPER_HORIZON, "paper": PAPER_HORIZON}
