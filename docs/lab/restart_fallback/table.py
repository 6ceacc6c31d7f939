"""The restart-fallback study's table: for each results folder given (one per float32 rounding), each dev seed's
chosen scout, its tail training loss, the continuations run (init seed: tail loss), the held-out L1 and whether
the first continuation kept its scout's loss.

    python docs/lab/restart_fallback/table.py default=/tmp/fbstudy/default reassoc=/tmp/fbstudy/reassoc
"""
import json
import sys
from pathlib import Path


def rows(label, folder):
    for f in sorted(Path(folder).glob("units/*/*/*/seed*/result.json")):
        d = json.loads(f.read_text())
        sc = d.get("scouting") or {}
        tails = dict(zip(sc.get("init_seeds", []), sc.get("tail_loss", []), strict=True))
        cont = sc.get("continued", [sc.get("chosen")])
        ctail = sc.get("continuation_tail_loss", [None])
        first = cont[0]
        kept = "yes" if ctail[0] is not None and ctail[0] <= tails[first] else "no"
        runs = ", ".join(f"{s}: {t:.3g}" if t is not None else str(s) for s, t in zip(cont, ctail, strict=True))
        yield (f"| {label} | {d['model']} | {d['seed']} | {first} | {tails[first]:.3g} | {runs} | {kept} | "
               f"{sc.get('chosen')} | {d['final_train_loss']:.3g} | {d['metrics']['heldout_l1']:.3g} |")


if __name__ == "__main__":
    print("| rounding | model | dev seed | first scout | its tail | continuations (init: tail) | first kept its "
          "scout's loss | kept | final training loss | held-out L1 |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for arg in sys.argv[1:]:
        label, _, folder = arg.partition("=")
        for r in rows(label, folder):
            print(r)
