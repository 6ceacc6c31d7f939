"""Two runs' verdicts side by side, part by part: whether a rerun (another CPU, another float32 rounding)
decides the same, and how far each part's interval lies from its threshold.

`rows(a, b, claims=None) -> pandas.DataFrame`: one row per claim, part and framework judged in either
`summary/verdicts.json`: the verdict in each run, whether they agree, each run's interval (point [lo, hi])
and the distance of its nearer end from the threshold (a factor >= 1; `verdicts.json`'s `distance`).
`python -m lagbench.reports.verdict_diff A/summary/verdicts.json B/summary/verdicts.json [--claims dp_loss,dp_energy]`
prints the table; exit status 0 when every verdict agrees, 1 otherwise.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import pandas as pd


def _parts(verdicts: dict, claims) -> dict:
    out = {}
    for c in verdicts.get("claims", []):
        if claims and c["id"] not in claims:
            continue
        out[(c["id"], "(claim)", "-")] = (c.get("verdict"), None)
        for p in c.get("parts") or []:
            for fw, verdict in (p.get("by_framework") or {}).items():
                out[(c["id"], p["name"], fw)] = (verdict, (p.get("interval") or {}).get(fw))
    return out


def _iv(iv) -> str:
    return "–" if not iv else f"{iv['point']:.3g} [{iv['lo']:.3g}, {iv['hi']:.3g}]"


def _dist(iv) -> str:
    d = (iv or {}).get("distance")
    return "–" if d is None else f"{d:.3g}"


def rows(a: dict, b: dict, claims=None) -> pd.DataFrame:
    pa, pb = _parts(a, claims), _parts(b, claims)
    out = []
    for key in sorted(set(pa) | set(pb)):
        (va, ia), (vb, ib) = pa.get(key, ("absent", None)), pb.get(key, ("absent", None))
        out.append({"claim": key[0], "part": key[1], "framework": key[2], "verdict A": va, "verdict B": vb,
                    "same": va == vb, "interval A": _iv(ia), "interval B": _iv(ib),
                    "distance A": _dist(ia), "distance B": _dist(ib)})
    return pd.DataFrame(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lagbench.reports.verdict_diff", description=__doc__.split("\n\n")[0])
    ap.add_argument("a", type=Path, help="a run's summary/verdicts.json")
    ap.add_argument("b", type=Path, help="another run's summary/verdicts.json")
    ap.add_argument("--claims", default="", help="claim ids, comma-separated (default: all)")
    args = ap.parse_args(argv)
    try:
        a, b = (json.loads(p.read_text()) for p in (args.a, args.b))
    except (OSError, json.JSONDecodeError) as e:
        print(f"verdict_diff: cannot read {e.filename or 'a verdicts file'}: {e}", file=sys.stderr)
        return 2
    df = rows(a, b, [c for c in args.claims.split(",") if c] or None)
    print(df.to_string(index=False))
    return 0 if df["same"].all() else 1


if __name__ == "__main__":
    raise SystemExit(main())
