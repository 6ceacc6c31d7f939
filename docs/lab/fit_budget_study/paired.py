"""The paired decision of docs/lab/fit_budget_study.md's extension: per fit seed, the dissipative LNN's test
rollout error over the baseline's (both fitted on the same file with the same seed), and the registered rule.

    python docs/lab/fit_budget_study/paired.py FOLDER [FOLDER ...]
"""
import sys
from math import comb
from pathlib import Path
from statistics import median

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "fit_friction_dp"))
from summary import fits  # noqa: E402  (the lab's reader of fit folders)

RIVAL, MODEL, KEY = "baseline", "lnn_dissipative", "test_rollout_gmean_err"


def errors(folder: str) -> dict:
    """{(folder, fit seed): {model: test rollout error}} of the fits under `folder` (the starved control aside)."""
    out: dict = {}
    for model, seed, r in fits(folder):
        out.setdefault((folder, seed), {})[model] = r["metrics"][KEY]
    return out


def sign_p(below: int, n: int) -> float:
    """One-sided sign test: the chance of at least `below` of `n` ratios under 1 when either way is even."""
    return sum(comb(n, k) for k in range(below, n + 1)) / 2 ** n


def decide(ratios: list) -> str:
    n, below = len(ratios), sum(r < 1 for r in ratios)
    if below >= n - 1 and median(ratios) <= 0.8:
        return "ahead"
    if n - below >= n - 1 and median(ratios) >= 1.25:
        return "behind"
    return "level"


if __name__ == "__main__":
    pairs = {}
    for folder in sys.argv[1:]:
        pairs.update(errors(folder))
    ratios = []
    print(f"| data | fit seed | {RIVAL} | {MODEL} | ratio |\n|---|---|---|---|---|")
    for (folder, seed), e in sorted(pairs.items()):
        if RIVAL in e and MODEL in e:
            ratios.append(e[MODEL] / e[RIVAL])
            print(f"| {folder} | {seed} | {e[RIVAL]:.4g} | {e[MODEL]:.4g} | {ratios[-1]:.3g} |")
    n, below = len(ratios), sum(r < 1 for r in ratios)
    print(f"\n{n} seeds: {below} with the {MODEL} below the {RIVAL}; median ratio {median(ratios):.3g} "
          f"(range {min(ratios):.3g}-{max(ratios):.3g}); one-sided sign test p = {sign_p(below, n):.3g}; "
          f"decision: {decide(ratios)}")
