"""`lagbench bench`: its command line (the study itself is `speedstudy.bench`)."""
from __future__ import annotations

import sys
from pathlib import Path


def cmd_bench(args):
    from lagbench.files.results import output_folder
    from lagbench.speedstudy import run_bench
    from lagbench.speedstudy.device import NoGPUError

    output_folder(Path(args.out), "--out")   # made and checked before any work
    try:
        run_bench(out=args.out, quick=not args.full, trained_from=args.trained_from, resume=args.resume,
                  gpu=args.gpu, stages=[x for x in (args.stages or "").split(",") if x.strip()])
    except NoGPUError as e:
        print(f"lagbench: error: {e}", file=sys.stderr)
        return 2


def add_bench(sub) -> None:
    s = sub.add_parser("bench", help="the speed study (writes OUT/bench/*.csv for the report)",
                       description="The speed study: inference, latency, training, rollouts, scaling, fast vs "
                       "paper, structure and train-to-target, each with JAX and PyTorch side by side. Writes "
                       "OUT/bench/*.csv, targets.json and machine.json (quick preset: about 20 min on 2 cores).")
    s.add_argument("--out", default="results/quick", help="results folder; writes OUT/bench/ (OUT/bench_gpu/ with "
                   "--gpu) (default: results/quick, which `lagbench report` reads unless given --results)")
    s.add_argument("--full", action="store_true", help="all batch sizes and grid sizes, slow (without it: the "
                   "quick preset)")
    s.add_argument("--trained-from", help="results folder whose training cache holds the learned models rolled "
                                          "out in the solver study (default: --out; else tiny models are trained)")
    s.add_argument("--resume", action="store_true", help="take the stages an interrupted run into --out finished "
                   "(same preset and commit) from OUT/bench/stages/ and run only the rest")
    s.add_argument("--gpu", action="store_true", help="run JAX and PyTorch on the CUDA GPU instead, at the GPU "
                   "preset (inference to batch 65536, training, scaling, fast vs paper); writes OUT/bench_gpu/ "
                   "(LAGBENCH_BENCH_TINY=1: a seconds-long check of the same stages)")
    s.add_argument("--stages", help="comma-separated stages to run, the rest skipped (default: all of the "
                   "preset's); e.g. control-rate. Stages: inference, single-sample-latency, control-rate, training, "
                   "rollouts, scaling, fast-vs-paper, structure, train-to-target, members")
    s.set_defaults(func=cmd_bench)
