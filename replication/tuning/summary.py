"""`python -m lagbench.replication.tuning.summary LEDGER.json ...`: the search ledgers as one Markdown table.

Per claim, profile and model: the configurations tried, the chosen one (as multiples of the registered
rate and widths), its development score (the mean over the confirmation seeds where confirmed, else the
first stage's), the registered setting's score on the same seeds, and the search's training time.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import pandas as pd


def _num(v) -> str:
    return "-" if v is None else f"{v:.4g}"


def rows(ledger: dict) -> list[dict]:
    out = []
    compute = ledger.get("compute") or {}
    for label, m in ledger["models"].items():
        conf = {int(k): v for k, v in (m.get("confirmation") or {}).items()}
        scores = {int(k): v for k, v in m["scores"].items()}
        k = m["chosen"]
        knobs = m["chosen_knobs"]
        out.append({"claim": ledger["claim"], "profile": ledger["profile"], "model": label,
                    "configs": m["configs_tried"],
                    "chosen": "-" if knobs is None else f"lr x{knobs['lr']:.3g}, width x{knobs['width']:g}",
                    "dev score": _num(conf.get(k, scores.get(k))),
                    "registered": _num(conf.get(0, scores.get(0))),
                    "seeds": ",".join(map(str, m.get("confirm_seeds") or ledger["seeds"])),
                    "train h": f"{(compute.get('by_model') or {}).get(label, 0.0) / 3600:.2f}"})
    return out


def table(paths) -> str:
    df = pd.DataFrame([r for p in paths for r in rows(json.loads(Path(p).read_text()))])
    header = "| " + " | ".join(df.columns) + " |\n|" + "---|" * len(df.columns) + "\n"
    return header + "".join("| " + " | ".join(map(str, r)) + " |\n" for r in df.itertuples(index=False))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m lagbench.replication.tuning.summary",
                                description="The ledgers of `lagbench tune` as one Markdown table.")
    p.add_argument("ledgers", nargs="+", metavar="LEDGER", help="ledger.json files")
    args = p.parse_args(argv)
    try:
        print(table(args.ledgers), end="")
    except (OSError, ValueError, KeyError) as e:
        p.exit(2, f"error: cannot read a ledger: {e}\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
