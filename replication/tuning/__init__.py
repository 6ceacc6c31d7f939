"""Equal tuning on the development split: one declared search, the same for every model of a claim
(`search.py`), run and ledgered by `tune.py` (`lagbench tune`)."""
