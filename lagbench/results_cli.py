"""The commands that read a results folder: `lagbench report` and `lagbench table` (`add_commands(sub)`)."""
from __future__ import annotations

import sys
from pathlib import Path

RESULT_ENTRIES = ("run.json", "claims.json", "units", "bench", "bench_gpu", "stiff", "train_target", "predict",
                  "control", "control_four_joint_arm", "online_four_joint_arm", "robustness")


def _results_folder(results: Path) -> Path:
    """--results, checked: a folder holding lagbench results (a one-line error otherwise)."""
    if not results.is_dir():
        raise ValueError(f"--results {results}: no such folder; give a folder written by `lagbench run` "
                         f"(or bench, stiff, train-target)")
    if not any((results / name).exists() for name in RESULT_ENTRIES):
        raise ValueError(f"--results {results}: holds no lagbench results (none of {', '.join(RESULT_ENTRIES)})")
    return results


def cmd_report(args):
    from lagbench import reports

    results = _results_folder(Path(args.results))
    out = Path(args.out) if args.out else Path("report") / (results.resolve().name or "results")
    paths = reports.build_report(results, out, pdf=not args.no_pdf)
    for k, v in paths.items():
        if k == "not_rebuilt":
            print(f"lagbench report: note: {', '.join(p.name for p in v)} in {out} not from this build (changed since "
                  f"written, or not on record): left as is", file=sys.stderr)
        else:
            print(f"{k}: {len(v)} files in {out / 'figures'}" if isinstance(v, list) else f"{k}: {v}")


def cmd_table(args):
    from lagbench.files.results import output_folder, write_csv
    from lagbench.reports.load import load_results
    from lagbench.reports.systems_table import by_table, excluded, mixed, shown, systems_table

    results = _results_folder(Path(args.results))
    res = load_results(results)
    df = systems_table(results, res)
    if args.system:
        df = df[df["system"] == args.system]
    if df.empty:
        raise ValueError(f"--results {results}: no model of {args.system or 'any system'} in it")
    left_out = excluded(results, res)
    if left_out:   # the units and records the numbers leave out, as the report names them
        print("lagbench table: " + "\n".join(left_out), file=sys.stderr)
    for line in mixed(df):   # rows of different profiles are never side by side
        print(f"lagbench table: {line}", file=sys.stderr)
    for title, g in by_table(df):
        print(f"{title}\n{shown(g).to_string(index=False)}\n")
    path = output_folder(results / "summary", "--results") / "systems.csv"
    write_csv(path, df)
    print(f"written to {path}")


def add_commands(sub) -> None:
    s = sub.add_parser("report", help="write REPORT.md, REPORT.pdf and figures from a results folder",
                       description="Write REPORT.md, REPORT.typ, REPORT.pdf and figures/*.png into --out from "
                       "the result files in --results, and APPENDIX.typ and APPENDIX.pdf (the long tables "
                       "REPORT.md holds in full). Replaces only files an earlier report wrote there.")
    s.add_argument("--results", default="results/quick", help="a folder written by `lagbench run` (or bench, "
                   "stiff, train-target) (default: results/quick)")
    s.add_argument("--out", help="the report folder (default: report/<the results folder's name>, so that "
                   "results/full gives report/full)")
    s.add_argument("--no-pdf", action="store_true", help="write REPORT.md and the figures only (no typesetting)")
    s.set_defaults(func=cmd_report)
    s = sub.add_parser("table", help="every model of a results folder per system, the suite's and yours (writes "
                       "RESULTS/summary/systems.csv)", description="A table per system and profile: each claim's "
                       "model and framework over its seeds (median [min, max]) and each predictor scored by evaluate "
                       "--predict. Rows of different profiles (a profile sets the training budget and the held-out "
                       "set) are printed in separate tables, with a note saying so.")
    s.add_argument("--results", default="results/quick", help="a folder written by `lagbench run` or evaluate "
                   "--predict; read, and the table written into it as RESULTS/summary/systems.csv (default: "
                   "results/quick)")
    s.add_argument("--system", help="one system only (default: every system in the folder)")
    s.set_defaults(func=cmd_table)
