"""PyTorch training under torch.compile (`replication.training.compile_torch`): the compiled phases give the
eager numbers up to rounding (float64, every step of a scouted run: stacked scouts, then the continuation;
and the relativistic LNN with its extra input under the weighted L1), a failed capture goes on eager with the same numbers, and when it compiles."""
import os

import numpy as np
import pytest
import torch
from parity_kit import compare, trace
from parity_rows import BY_NAME

from lagbench.models import ModelSpec, init_params
from lagbench.replication.training import compile_torch, train_torch
from lagbench.replication.training.data import BatchStream
from lagbench.replication.training.outcome import joined_modes


def _traced(monkeypatch, setting, row):
    monkeypatch.setenv(compile_torch.ENV, setting)
    return trace("torch", row)


@pytest.mark.parametrize("name", ["lnn_scouted", "lnn_l1_gamma"])
def test_compiled_training_equals_eager_up_to_rounding(monkeypatch, name):
    row = BY_NAME[name]
    eager = _traced(monkeypatch, "off", row)
    compiled = _traced(monkeypatch, "on", row)
    diffs, mismatches = compare(eager, compiled)
    assert not mismatches, mismatches
    assert diffs["steps"] >= row.protocol.steps
    for k in ("loss", "grad_norm", "params"):
        assert diffs[k] < 1e-9, (k, diffs)
    assert set(compiled.modes) == {"compiled"} and set(eager.modes) == {"eager"}
    if name == "lnn_scouted":
        assert len(compiled.modes) == 2 and compiled.outcome.step_mode == "compiled"


def test_a_failed_capture_trains_eager_from_the_same_state(monkeypatch, caplog):
    row = BY_NAME["lnn_fast"]
    spec, p = row.spec, row.protocol.replace(steps=3)

    def broken(fn, **_):
        def call(*args):
            raise RuntimeError("no C++ compiler")
        return call
    monkeypatch.setattr(compile_torch.torch, "compile", broken)
    runs = {}
    for setting in ("off", "on"):
        monkeypatch.setenv(compile_torch.ENV, setting)
        runs[setting] = train_torch.train(spec, init_params(spec, seed=0), p, BatchStream(p, 0))
    assert runs["on"].step_mode == "eager (torch.compile failed: RuntimeError)"
    assert runs["off"].step_mode == "eager"
    assert [r["loss"] for r in runs["on"].log] == [r["loss"] for r in runs["off"].log]
    for k, v in runs["off"].params.items():
        np.testing.assert_array_equal(runs["on"].params[k], v)
    assert "torch.compile failed, training eager: RuntimeError: no C++ compiler" in caplog.text


def test_when_a_phase_compiles(monkeypatch):
    lnn = ModelSpec(kind="lnn", dof=2, hidden=(8, 8))
    paper, hnn = ModelSpec(kind="lnn", dof=2, hidden=(8, 8), formulation="paper"), ModelSpec(kind="hnn", dof=1)
    baseline = ModelSpec(kind="baseline", dof=2, hidden=(8, 8))
    short = BY_NAME["lnn_fast"].protocol
    long = short.replace(steps=-(-compile_torch.COMPILE_MIN_SAMPLES // short.batch))
    monkeypatch.delenv(compile_torch.ENV, raising=False)
    assert compile_torch.wanted(lnn, long) and not compile_torch.wanted(lnn, short)
    assert compile_torch.wanted(lnn, long.replace(steps=long.steps // 4), members=4)   # side by side: their samples
    assert not compile_torch.wanted(lnn, long.replace(steps=long.steps // 4 - 1), members=4)
    assert not compile_torch.wanted(paper, long) and not compile_torch.wanted(hnn, long)   # torch.func maths
    assert not compile_torch.wanted(baseline, long)   # its matrix products: no gain
    monkeypatch.setenv(compile_torch.ENV, "on")
    assert compile_torch.wanted(lnn, short) and not compile_torch.wanted(paper, short)
    monkeypatch.setenv(compile_torch.ENV, "off")
    assert not compile_torch.wanted(lnn, long)
    monkeypatch.setenv(compile_torch.ENV, "sometimes")
    with pytest.raises(ValueError, match="LAGBENCH_TORCH_COMPILE='sometimes'; valid: auto, on, off"):
        compile_torch.wanted(lnn, long)


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX owners and modes")
def test_no_private_inductor_cache_trains_eager(monkeypatch, tmp_path):
    """Where inductor's folder is not this user's own (`models.torch.inductor_cache`), a stepper trains eager."""
    monkeypatch.setenv("TORCHINDUCTOR_CACHE_DIR", "unused")
    monkeypatch.delenv("TORCHINDUCTOR_CACHE_DIR")
    (tmp_path / "torchinductor").mkdir()
    (tmp_path / "torchinductor").chmod(0o777)
    monkeypatch.setenv("LAGBENCH_CACHE", str(tmp_path))
    row = BY_NAME["lnn_fast"]
    monkeypatch.setenv(compile_torch.ENV, "on")
    assert train_torch.Stepper(row.spec, init_params(row.spec, seed=0), row.protocol).mode == "eager"


def test_joined_modes_name_each_phase_mode_once_in_order():
    assert joined_modes("compiled", "compiled") == "compiled"
    assert joined_modes("eager", "compiled", "eager + compiled") == "eager + compiled"
    assert joined_modes(None, "jit") == "jit" and joined_modes(None, None) is None


def test_compiling_is_not_tracing_or_exporting():
    from lagbench.models.torch import export_paths

    assert not export_paths.compiling() and not export_paths.tracing()
    seen = {}

    def f(x):
        seen["compiling"], seen["tracing"] = export_paths.compiling(), export_paths.tracing()
        return x + 1
    torch.compile(f, fullgraph=True, backend="eager")(torch.ones(2))
    assert seen == {"compiling": True, "tracing": False}


def test_estimate_probes_compile_where_the_phase_they_stand_for_will(monkeypatch):
    lnn = ModelSpec(kind="lnn", dof=2, hidden=(8, 8))
    long = BY_NAME["lnn_fast"].protocol.replace(steps=compile_torch.COMPILE_MIN_SAMPLES)
    probe = long.replace(steps=8)
    monkeypatch.delenv(compile_torch.ENV, raising=False)
    with compile_torch.like(lnn, long):
        assert compile_torch.wanted(lnn, probe)
    assert not compile_torch.wanted(lnn, probe) and compile_torch.ENV not in os.environ
    monkeypatch.setenv(compile_torch.ENV, "off")
    with compile_torch.like(lnn, long):
        assert not compile_torch.wanted(lnn, probe)
    assert os.environ[compile_torch.ENV] == "off"


def test_without_a_cxx_compiler_training_is_eager_with_one_warning(monkeypatch, caplog):
    import shutil

    from lagbench.replication.training import compile_torch as ct

    monkeypatch.setattr(shutil, "which", lambda name: None)
    monkeypatch.setattr(ct, "_WARNED", set())
    monkeypatch.setattr(ct, "wanted", lambda *a, **k: True)
    monkeypatch.setattr(ct.inductor_cache, "private", lambda: True)
    fn = lambda m, b: 0.0  # noqa: E731
    with caplog.at_level("WARNING", logger="lagbench"):
        assert ct.compiled_loss(fn, None, None) is fn and ct.compiled_loss(fn, None, None) is fn
    assert sum("C++ compiler" in r.getMessage() for r in caplog.records) == 1
