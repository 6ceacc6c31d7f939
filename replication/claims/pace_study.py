"""The settings claims 6 and 7 share (the training-pace studies on the double pendulum): widths, protocols,
seeds, the end-state bar's level and what the reported share counts. Shared constants, not a claim."""
from lagbench.replication.claims import double_pendulum as dp
from lagbench.replication.training.protocol import Tracking
from lagbench.replication.training.scouting import scout_protocol

WIDTHS = {"smoke": dp.SMOKE_W, "quick": dp.QUICK_W, "full": dp.QUICK_W, "paper": dp.PAPER_W}
# quick: 1.6e5 samples a seed at batch 32, sized to the 45-minute budget. Measured (8 seeds, 3 x 64, JAX and
# PyTorch alike): cranmer2020 runs left the plateau after 2750-6750 steps, kaiming's after 750-4000
PACE_STEPS = 5000
_scout = scout_protocol(dp.RESTARTS)   # the claims 1-2 scouts: batch 32, peak 1e-3, guard
PROTOCOLS = {"smoke": scout_protocol(dp.unkept(dp.PROTOCOLS["smoke"])).replace(cohort=2),
             "quick": _scout.replace(steps=PACE_STEPS, data=_scout.data.replace(n_heldout=10_000), log_every=100, cohort=8,
                                     tracking=Tracking(every=500)),
             "full": _scout.replace(data=_scout.data.replace(n_heldout=20_000), log_every=100, cohort=8,
                                    tracking=Tracking(every=500)),
             "paper": dp.PROTOCOLS["paper"].replace(steps=40_000)}
# seeds a model: at least `stats.seeds_needed(0.05, rivals)` (7 for 3 or 5 rivals) in every profile that
# decides (`tests/replication/claims/test_claims_records.py`); smoke's 2 decide nothing, by design
SEEDS = {"smoke": 2, "quick": 8, "full": 16, "paper": 8}
# the end state: a pace study reads its reference only once it has left the plateau on held-out states
# (held-out L1 at most half the null predictor's, the level that counts as leaving)
LEFT = 0.5
# what the reported share counts (the verdict counts pace: samples until the training loss left)
METRIC_LABEL = "share of seeds whose held-out L1 is off the q-double-dot ~ 0 plateau at the end of the budget"
