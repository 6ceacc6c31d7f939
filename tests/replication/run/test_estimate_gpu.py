"""On a GPU (or with `--pack-seeds`) each model's seeds pack into training programs (`run.gpu_cohorts.programs`),
and the estimate adds what the run takes so: per program, the probed seconds per step of its members side by
side x its steps, summed, and handed to the workers longest first (`run.estimate`), printed by
`run.announce`. The probes are faked here: no training."""
import pytest

from lagbench.replication.claims import CLAIMS
from lagbench.replication.claims.resolved import resolved
from lagbench.replication.run import estimate as E
from lagbench.replication.run import gpu_cohorts as G
from lagbench.replication.run.announce import announce
from lagbench.replication.run.runner import plan
from lagbench.replication.training import device as dev
from lagbench.replication.training.train import train_key

PLAIN = 0.01                                                  # seconds a step of one model
MEMBERS = {k: PLAIN * (1 + 0.1 * k) for k in range(2, 9)}     # of k models side by side
CLAIM_IDS = ("dp_loss", "init_study", "hnn_energy")          # 5, 8 and 5 seeds a model


@pytest.fixture
def probes(monkeypatch):
    calls = []
    monkeypatch.setattr(E, "_plain_step", lambda *a: calls.append(1) or PLAIN)
    monkeypatch.setattr(E, "_members_step", lambda fw, spec, p, k: calls.append(k) or MEMBERS[k])
    return calls


@pytest.fixture
def on_gpu(monkeypatch):
    monkeypatch.setattr(dev, "resolve", lambda req, fw: "gpu")


def _cache(out, u):
    folder = out / "trained" / u.framework / train_key(u.framework, u.spec(), u.protocol(), u.seed)
    folder.mkdir(parents=True)
    (folder / "result.json").write_text("{}")


def _packed_seconds(claim_ids, profile="paper") -> list:
    """Per trained model of the claims: MEMBERS[its seeds] x its steps (the docstring's sum, by hand)."""
    out = []
    for cid in claim_ids:
        r = resolved(CLAIMS[cid], profile)
        out += [MEMBERS[r.seeds] * m.protocol.steps for m in r.models if m.train]
    return out


def test_a_models_seeds_pack_into_one_program_and_a_cached_seed_stays_out(tmp_path):
    units = plan("paper", claims=["dp_loss", "dp_energy"], frameworks=("jax",), models=["lnn"])
    seeds = sorted({u.seed for u in units})
    (prog,) = G.programs(units, tmp_path)   # the two claims share each seed's training
    assert prog.packed and prog.seeds == tuple(seeds) and len(prog.units) == len(units) == 2 * len(seeds)
    assert prog.protocol == units[0].protocol() and prog.protocol.cohort is None   # no cohort written in
    assert [p.seeds for p in G.programs(units, tmp_path, members=2)] == [tuple(seeds[i:i + 2])
                                                                          for i in range(0, len(seeds), 2)]
    _cache(tmp_path, units[0])
    (prog,) = G.programs(units, tmp_path)
    assert prog.seeds == tuple(s for s in seeds if s != units[0].seed)
    with pytest.raises(ValueError, match="members"):
        G.programs(units, tmp_path, members=0)


def test_a_protocol_with_restarts_or_its_own_cohort_keeps_its_programs(tmp_path):
    scouted = plan("quick", claims=["dp_loss"], frameworks=("jax",), models=["lnn"])
    assert "restarts" in G.blocker(scouted[0].protocol())
    progs = G.programs(scouted, tmp_path)
    assert [p.seeds for p in progs] == [(u.seed,) for u in scouted] and not any(p.packed for p in progs)
    cohort = plan("quick", claims=["init_study"], frameworks=("jax",), models=["lnn_init-xavier"])
    k = cohort[0].protocol().cohort
    assert G.blocker(cohort[0].protocol()) == f"a cohort of {k} already (its protocol's own)"
    (prog,) = G.programs(cohort, tmp_path)
    assert not prog.packed and prog.members == k == len(prog.seeds)


@pytest.mark.parametrize("jobs", [1, 2])
def test_the_gpu_estimate_is_the_docstrings_sum_and_the_run_prints_it(tmp_path, probes, on_gpu, capsys, jobs):
    units = plan("paper", claims=list(CLAIM_IDS), frameworks=("jax",))
    est = E.estimate(units, tmp_path, jobs=jobs)
    seconds = sorted(_packed_seconds(CLAIM_IDS), reverse=True)
    c = est["cohorts"]
    assert c["train_s"] == pytest.approx(sum(seconds)) and c["seconds"] == pytest.approx(seconds)
    assert c["programs"] == len(seconds) and c["members"] == 8
    assert c["wall_s"] == pytest.approx(E.scheduled_wall(seconds, jobs))
    assert (c["wall_s"] == pytest.approx(c["train_s"])) if jobs == 1 else (max(seconds) <= c["wall_s"] < c["train_s"])
    # one seed a program, as the run trains them: each seed's steps at the plain probe
    alone = sum(PLAIN * m.protocol.steps * r.seeds for r in (resolved(CLAIMS[i], "paper") for i in CLAIM_IDS)
                for m in r.models if m.train)
    assert est["train_s"] == pytest.approx(alone) and alone > c["train_s"]
    # a claim sharing these trainings adds no program
    again = E.estimate(plan("paper", claims=[*CLAIM_IDS, "dp_energy"], frameworks=("jax",)), tmp_path, jobs=jobs)
    assert again["cohorts"]["train_s"] == pytest.approx(c["train_s"])
    announce("paper", units, units, tmp_path, jobs)
    printed = capsys.readouterr().out
    assert (f"{c['programs']} programs of up to 8 seeds; this run trains one seed a program): "
            f"{sum(seconds) / 3600:.1f} h of training, about {E.scheduled_wall(seconds, jobs) / 3600:.1f} h wall "
            f"with {jobs} worker") in printed


def test_a_cached_seed_leaves_a_smaller_program_and_the_probes_are_kept(tmp_path, probes, on_gpu):
    units = plan("paper", claims=["dp_loss"], frameworks=("jax",), models=["lnn"])
    _cache(tmp_path, units[0])
    est = E.estimate(units, tmp_path, keep=True)
    n = len(units) - 1
    assert est["cohorts"]["train_s"] == pytest.approx(MEMBERS[n] * units[0].protocol().steps) and n in probes
    probes.clear()
    again = E.estimate(units, tmp_path)   # the same machine: the cohort's probe is read back, not timed again
    assert not probes and again["cohorts"] == est["cohorts"]


def test_a_blocked_protocol_costs_what_the_plain_estimate_gives_it(tmp_path, probes, on_gpu):
    units = plan("quick", claims=["init_study"], frameworks=("jax",))
    est = E.estimate(units, tmp_path)
    assert est["cohorts"]["train_s"] == pytest.approx(est["train_s"]) == pytest.approx(sum(_packed_seconds(
        ["init_study"], "quick")))


def test_on_the_cpu_nothing_is_packed(tmp_path, probes, monkeypatch, capsys):
    monkeypatch.setattr(dev, "resolve", lambda req, fw: "cpu")
    units = plan("paper", claims=["dp_loss"], frameworks=("jax",), models=["lnn"])
    est = announce("paper", units, units, tmp_path, 1)
    assert "cohorts" not in est and "packed" not in capsys.readouterr().out


def test_on_the_cpu_a_run_that_packs_seeds_is_estimated_at_its_own_packing(tmp_path, probes, monkeypatch, capsys):
    monkeypatch.setattr(dev, "resolve", lambda req, fw: "cpu")
    units = plan("paper", claims=["dp_loss"], frameworks=("jax",), models=["lnn"])
    n = len(units)
    est = announce("paper", units, units, tmp_path, 1, members={"jax": 3})
    c, steps = est["cohorts"], units[0].protocol().steps
    assert c["members"] == 3 and c["programs"] == -(-n // 3)
    sizes = [3] * (n // 3) + ([n % 3] if n % 3 else [])
    assert c["train_s"] == pytest.approx(sum((MEMBERS[k] if k > 1 else PLAIN) * steps for k in sizes))
    printed = capsys.readouterr().out
    assert f"packed as one program ({c['programs']} programs of up to 3 seeds; as this run packs them)" in printed
    # the same run on a GPU: still at the run's own packing, not at MAX_MEMBERS
    monkeypatch.setattr(dev, "resolve", lambda req, fw: "gpu")
    assert E.estimate(units, tmp_path, members={"jax": 3})["cohorts"]["members"] == 3
