"""Progress of an evaluation's rollouts on the console (`lagbench fit` and `evaluate`): `RolloutBars`, one tqdm
bar per evaluation set, made at its first report and closed when its rollouts are done."""
from __future__ import annotations


class RolloutBars:
    """tqdm bars for an evaluation's rollouts, one per evaluation set: `bars(label, done, total)`."""

    def __init__(self, quiet: bool, prefix: str):
        self.quiet, self.prefix, self.bars = quiet, prefix, {}

    def __call__(self, label, done, total):
        from tqdm.auto import tqdm

        if label not in self.bars:
            self.bars[label] = tqdm(total=total, desc=f"{self.prefix} rollouts ({label})", unit="sample",
                                    disable=self.quiet)
        bar = self.bars[label]
        bar.update(min(done, total) - bar.n)
        if done >= total:
            bar.close()

    def close(self):
        for bar in self.bars.values():
            bar.close()
        self.bars = {}
