"""The speed study's numeric targets, one declared table (what each means: `speedstudy.targets`;
the train-to-target bound, the paper's L1 within a tenth of the original's samples, is in
`speedstudy.train_target`)."""

TARGETS = {
    "fast_over_paper": {2: 1.25, 16: 1.8},
    "roofline_fraction": 0.8,
    "jax_over_torch": 1.5,
    "lgn_banded_exponent": 1.1,
    "lgn_banded_over_dense": 50,
    "delan_single_sample_per_s": 1e4,
    "members_cost_vs_one": 2.5,
}
