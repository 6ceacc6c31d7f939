"""The speed study: `run_bench(out, quick=True, tiny=False, trained_from=None)` writes OUT/bench/ (what
`lagbench bench` calls). Learned-model rollouts take their parameters from the training cache of
`trained_from` (default OUT: `lagbench bench --out results/quick` uses the quick run's models) and
otherwise train tiny ones.

Files (all CSV with a header row, written atomically; columns beyond these are extras the report may
ignore):
  machine.json    cpu, cores, gpu (or null), platform, thread settings, versions, commit, date, preset
  inference.csv   system, model, formulation, framework, dtype, batch, samples_per_s, error, source, hidden,
                  ops (`speedstudy.inference`)
  latency.csv     system, model, method, framework, dtype, mode, dispatch, threads, hidden, evals_per_s,
                  max_abs_diff, ops: DeLaN one-sample calls (`speedstudy.latency`; JAX through
                  `models.jax.compiled.compile_single`)
  control_rate.csv model, framework, mode, ticks, mean_us, median_us, p99_us, rate_hz_mean, rate_hz_p99,
                  fits_500hz_mean, fits_500hz_p99, ...: control ticks per second each learned inverse model of the
                  two-link arm sustains on one core in the 500 Hz computed-torque loop, inference alone and
                  with online learning (`speedstudy.control_rate`; quick and full presets only)
  training.csv    system, model, framework, mode, dtype, batch, steps_per_s, samples_per_s, hidden
                  (`speedstudy.training`)
  rollout.csv     system, solver, rtol, kind, model, source, wall_s, state_err, energy_err, dt, n_ics, t_end
                  (`speedstudy.rollout`; kind truth | chaos_floor | learned | learned_tiny)
  train_target.csv / train_target_log.csv  samples to reach held-out L1 thresholds, per protocol, and the
                  held-out L1 against samples consumed (`speedstudy.train_target`)
  scaling.csv     study, formulation, framework, n, seconds_per_eval, samples_per_s, batch
  scaling_fit.csv study, formulation, framework, exponent, n_min, n_max   (`speedstudy.scaling`)
  fast_paper.csv  dof, framework, formulation, mode, batch, seconds, samples_per_s, flops_per_sample, gflops, threads
  matmul.csv      dof, framework, rows, seconds, gflops, threads           (`speedstudy.roofline`)
  structure.csv   per system: declared structure and what using it buys   (`speedstudy.structure`)
  members.csv     framework, mode, members, hidden, batch, steps, wall_s, step_s, samples_per_s, cost_vs_one:
                  K models trained as one program against one alone, and one at K x the batch, per step
                  mode (PyTorch eager and torch.compile) (`speedstudy.members`)
  ratios.csv      operation, jax, torch, ratio, note                       (`speedstudy.tables`)
  targets.json    the issue's numeric targets (`speedstudy.targets.TARGETS`), each with the measured
                  values and met: true/false
  timings.json    wall seconds of the whole study and per stage, and the stages taken from checkpoints
  stages/*.json   one checkpoint per finished stage, for `lagbench bench --resume` (`speedstudy.resume`)
Presets (`speedstudy.timing`): quick (default), full (`quick=False`), tiny (`tiny=True` or the
environment variable LAGBENCH_BENCH_TINY=1: seconds, for the tests). With gpu=True (`lagbench bench
--gpu`) both frameworks run on one CUDA GPU (`speedstudy.device`) at the GPU preset, whose stages
are inference, training, scaling and fast vs paper, into OUT/bench_gpu/ (same files; machine.json adds
the device). Every figure is a throughput or a ratio within this one run; numbers from different
machines (machine.json) are never to be mixed.
PyTorch runs with `TORCH_THREADS` (1) intra-op threads: on two shared cores its OpenMP pool at 2 threads
ran 10-100x slower than on 1 (threads waiting at barriers while other processes hold the cores); JAX
keeps XLA's defaults (the thread settings are recorded in machine.json). The inference rows are the
exception, and so are the fast/paper and matmul rows: each PyTorch row is timed at 1 thread and at all
cores and keeps the faster (its `threads` column), so that at large batches PyTorch is not held to half
the cores XLA uses; PyTorch compiled ahead of time (mode "aoti", `evaluators.TorchAotEvaluator`; mode "traced" for
the torch.func models, `evaluators.TorchTracedEvaluator`) has its own rows beside eager. Both compiled
modes call large batches of the LNN and the dense LGN in the row blocks the JAX models compute them in
(`models.row_blocks`), so that the two frameworks do the same work per block.
"""
from __future__ import annotations

__all__ = ["run_bench"]


def run_bench(*args, **kwargs):
    """`speedstudy.bench.run_bench`: imported when called, so that importing the package imports no framework."""
    from lagbench.speedstudy.bench import run_bench as run

    return run(*args, **kwargs)
