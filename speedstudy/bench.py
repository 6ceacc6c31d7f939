"""The speed study's orchestrator: `run_bench` runs the stages of `speedstudy.timing.STAGES` in order, each
checkpointed (`speedstudy.resume`), and writes OUT/bench/ (the files and presets: `speedstudy`'s docstring)."""
from __future__ import annotations

import dataclasses
import os
import time
from contextlib import nullcontext
from pathlib import Path

import pandas as pd
import torch
from tqdm.auto import tqdm

from lagbench.files.results import write_csv, write_json
from lagbench.replication.run import environment
from lagbench.speedstudy import (
    control_rate,
    device,
    latency,
    learned,
    members,
    rollout,
    roofline,
    scaling,
    structure,
    tables,
    train_target,
    training,
)
from lagbench.speedstudy import inference as INF
from lagbench.speedstudy import targets as TG
from lagbench.speedstudy.resume import StageCache
from lagbench.speedstudy.timing import FULL, GPU, GPU_TINY, QUICK, STAGES, TINY, TORCH_THREADS, Sizes


def machine(sizes) -> dict:
    return {**environment.hardware(), "versions": environment.versions(), "commit": environment.commit(),
            "date": environment.now(), "preset": sizes.name, "stages": list(sizes.stages or STAGES),
            **device.settings(),
            "torch_threads": TORCH_THREADS, "jax_threads": "XLA default",
            "xla_flags": os.environ.get("XLA_FLAGS", ""), "torch_config": torch.__config__.parallel_info()
            .splitlines()[:6]}


def _write(bench: Path, name: str, rows: list[dict]) -> None:
    write_csv(bench / f"{name}.csv", pd.DataFrame(rows))


def run_bench(out, quick: bool = True, tiny: bool | None = None, progress: bool = True,
              trained_from=None, resume: bool = False, gpu: bool = False, sizes: Sizes | None = None,
              stages=None) -> dict:
    """Run the study into OUT/bench/ (OUT/bench_gpu/ with gpu=True); returns the targets dict (also written
    as targets.json).

    trained_from: a results folder whose training cache (trained/jax/...) holds double-pendulum models
    for the learned rollouts (default OUT itself; where none is found a tiny model is trained).
    resume: take the stages an earlier run into OUT finished, at the same preset and commit, from their
    checkpoints (OUT/bench/stages/, `speedstudy.resume`) instead of running them again.
    gpu: run both frameworks on the CUDA GPU (`device.gpu_session`; NoGPUError, before anything is
    written, where either framework sees none) at the GPU preset (GPU_TINY when tiny), its stages only.
    sizes: a preset to use instead (tests).
    stages: run only these stages of `STAGES` (names as there, or with "-" or "_" for the spaces); a
    ValueError naming the unknown ones before anything is written."""
    if tiny is None:
        tiny = os.environ.get("LAGBENCH_BENCH_TINY", "") not in ("", "0")
    if sizes is None:
        sizes = (GPU_TINY if tiny else GPU) if gpu else (TINY if tiny else (QUICK if quick else FULL))
    if stages:
        def norm(x):
            return str(x).strip().lower().replace("-", " ").replace("_", " ")
        named = {norm(s): s for s in STAGES}
        sizes = dataclasses.replace(sizes, stages=tuple(named.get(norm(x), str(x).strip()) for x in stages))
    unknown = [s for s in sizes.stages if s not in STAGES]
    if unknown:
        raise ValueError(f"preset {sizes.name}: unknown stages {unknown}; valid: {', '.join(STAGES)}")
    with device.gpu_session() if gpu else nullcontext():
        out = Path(out)
        bench = out / ("bench_gpu" if gpu else "bench")
        bench.mkdir(parents=True, exist_ok=True)
        old_threads = torch.get_num_threads()
        torch.set_num_threads(TORCH_THREADS)
        info = machine(sizes)
        write_json(bench / "machine.json", info)
        cache = StageCache(bench, sizes.name, info["commit"], resume)
        try:
            return _run(out, bench, sizes, progress, Path(trained_from) if trained_from else out, cache)
        finally:
            torch.set_num_threads(old_threads)


class _Stages:
    """Runs the study's stages: each one's tables written as CSV and checkpointed (or, on resume, taken
    from its checkpoint); wall seconds per stage kept for timings.json."""

    def __init__(self, bar, bench: Path, cache: StageCache, notes: list, stages: tuple = STAGES):
        self.bar, self.bench, self.cache, self.notes, self.seconds = bar, bench, cache, notes, {}
        self.stages = stages

    def __call__(self, name: str, n_cases: int, compute, files=()) -> dict:
        """compute() -> {file name: rows}, run unless a checkpoint stands in for it, or the preset leaves
        the stage out (then {file: []} for each of `files`, nothing written)."""
        if name not in self.stages:
            self.bar.update(n_cases)
            return {f: [] for f in files}
        self.bar.set_postfix_str(name)
        t0 = time.perf_counter()
        try:
            got = self.cache.load(name)
            if got is not None:
                tables, notes = got
                self.notes += notes
                self.bar.update(n_cases)
            else:
                before = len(self.notes)
                tables = compute()
                self.cache.save(name, tables, self.notes[before:])
            for file, rows in tables.items():
                _write(self.bench, file, rows)
            return tables
        finally:
            self.seconds[name] = self.seconds.get(name, 0.0) + time.perf_counter() - t0


def _run(out: Path, bench: Path, sizes, progress: bool, trained_from: Path, cache: StageCache) -> dict:
    notes: list[str] = [f"PyTorch on {TORCH_THREADS} intra-op thread(s) (inference rows: the faster of "
                        f"{' and '.join(map(str, INF.TORCH_THREAD_CHOICES))}); JAX with XLA's default threads"]
    cases = INF.inference_cases(sizes) + INF.trained_cases(out, (1, max(sizes.batches)))
    sc_cases = list(scaling.lgn_cases(sizes)) + list(scaling.chain_cases(sizes))
    total = (len(cases) + 1 + training.n_training_cases(sizes) + rollout.n_rollout_cases(sizes) + len(sc_cases)
             + 2 * len(sizes.ratio_dofs) + structure.n_structure_cases() + train_target.n_cases(sizes)
             + members.n_cases(sizes) + (1 if sizes.control_s else 0))
    bar = tqdm(total=total, desc=f"lagbench bench ({sizes.name})", unit="case", disable=not progress)
    stage, t_start = _Stages(bar, bench, cache, notes, sizes.stages or STAGES), time.perf_counter()
    if sizes.stages:
        notes.append(f"preset {sizes.name}: stages {', '.join(sizes.stages)} only")
    if device.on_gpu():
        notes[0] = "GPU run: JAX jit and PyTorch eager on the same CUDA device, full float32 matrix products"
    try:
        inf_rows = stage("inference", len(cases),
                         lambda: {"inference": _inference(cases, sizes, notes, bar)}, ["inference"])["inference"]
        lat_rows = stage("single-sample latency", 1, lambda: _latency(sizes, notes, bar), ["latency"])["latency"]
        if sizes.control_s:   # a preset with no control-rate seconds has no such stage
            stage("control rate", 1, lambda: _control_rate(sizes, notes, bar), ["control_rate"])
        train_rows = stage("training", training.n_training_cases(sizes),
                           lambda: {"training": training.training_rows(sizes, notes, bar)}, ["training"])["training"]
        stage("rollouts", rollout.n_rollout_cases(sizes),
              lambda: {"rollout": rollout.rollout_rows(sizes, bar, trained_from=trained_from, notes=notes,
                                                             learned_rows=learned.learned_rollout_rows)})
        sc = stage("scaling", len(sc_cases), lambda: _scaling(sc_cases, sizes, bar), ["scaling", "scaling_fit"])
        sc_rows, fit = sc["scaling"], sc["scaling_fit"]
        fp = stage("fast vs paper", 2 * len(sizes.ratio_dofs), lambda: _fast_paper(sizes, bar),
                   ["fast_paper", "matmul"])
        fp_rows, mm_rows = fp["fast_paper"], fp["matmul"]
        stage("structure", structure.n_structure_cases(),
              lambda: {"structure": structure.structure_rows(sizes, inf_rows, bar)})
        tt_rows = stage("train to target", train_target.n_cases(sizes),
                        lambda: _train_target(sizes, bar), ["train_target"])["train_target"]
        mb_rows = stage("members", members.n_cases(sizes),
                        lambda: {"members": members.members_rows(sizes, bar) if sizes.members_steps else []},
                        ["members"])["members"]
    finally:
        bar.close()
        write_json(bench / "timings.json", {"preset": sizes.name, "total_s": time.perf_counter() - t_start,
                                            "stages_s": stage.seconds, "resumed_stages": cache.reused})
    ratios = tables.ratio_rows(inf_rows, train_rows, sc_rows, fp_rows, mm_rows, notes, lat_rows)
    _write(bench, "ratios", ratios)
    targets = TG.targets(ratios, fit, sc_rows, inf_rows, train_rows, lat_rows, tt_rows, mb_rows)
    write_json(bench / "targets.json", {"preset": sizes.name, "targets": targets})
    return targets


def _latency(sizes, notes, bar) -> dict:
    rows = latency.latency_rows(sizes, notes)
    bar.update(1)
    return {"latency": rows}


def _control_rate(sizes, notes, bar) -> dict:
    rows = control_rate.control_rate_stage(sizes, notes)
    bar.update(1)
    return {"control_rate": rows}


def _scaling(sc_cases, sizes, bar) -> dict:
    rows = []
    for group in scaling.scaling_groups(sc_cases):
        st, form, fw = group[0][:3]
        bar.set_postfix_str(f"scaling {st} {form} {fw} n={','.join(str(c[3]) for c in group)}")
        rows += scaling.run_scaling_group(group, sizes)
        bar.update(len(group))
    return {"scaling": rows, "scaling_fit": scaling.fit_exponents(rows)}


def _train_target(sizes, bar) -> dict:
    rows, log = train_target.train_target_rows(sizes, bar)
    return {"train_target": rows, "train_target_log": log}


def _fast_paper(sizes, bar) -> dict:
    fp_rows, mm_rows = [], []
    for d in sizes.ratio_dofs:
        fp, mm = roofline.roofline_rows(sizes, d)
        fp_rows += fp
        mm_rows += mm
        bar.update(2)
    return {"fast_paper": fp_rows, "matmul": mm_rows}


def _inference(cases, sizes, notes, bar) -> list[dict]:
    rows, states = [], {}
    for c in cases:
        key = (c.system, tuple(sorted(c.system_kw.items())))
        if key not in states:
            states[key] = INF.states_for(c.system, c.system_kw, max(sizes.batches))
        bar.set_postfix_str(f"{c.system} {c.model}/{c.formulation} {c.framework} {c.dtype}")
        try:
            rows += INF.run_case(c, states[key], sizes.min_time)
        except Exception as exc:  # a model that cannot run is a result, not the end of the study
            notes.append(f"inference {c.system} {c.model}/{c.formulation} {c.framework} {c.dtype}: "
                         f"{type(exc).__name__}: {str(exc).splitlines()[0][:160] if str(exc) else ''}")
        bar.update(1)
    return rows
