"""The run's progress bar advances by each unit's estimated seconds (`unit_seconds`), not by a unit count: its
total is their sum, a training shared by two units counts once, a cached one not at all."""
import pytest
from inline_workers import inline_workers

from lagbench.replication.run import executor, runner
from lagbench.replication.run import unit_seconds as W
from lagbench.replication.training.train import group_key, train_key


class Bars:
    """tqdm, recording each bar's total and what it advanced by."""
    made: list = []

    def __init__(self, *args, total=None, **kwargs):
        self.total, self.n, self.kwargs = total, 0.0, kwargs
        Bars.made.append(self)

    def update(self, n=1):
        self.n += n

    def set_postfix_str(self, *a, **k):
        pass

    set_postfix = set_postfix_str

    def close(self):
        pass


@pytest.fixture
def bars(monkeypatch):
    Bars.made = []
    monkeypatch.setattr(executor, "tqdm", Bars)
    monkeypatch.setattr(executor, "_one", lambda u, out, on_log=None: (None, None))   # no training here
    return Bars.made


def _outer(made):
    (bar,) = [b for b in made if "bar_format" in b.kwargs]
    return bar


def test_a_shared_training_counts_once_and_a_cached_one_not_at_all(tmp_path):
    todo = runner.plan("smoke", claims=["dp_loss", "dp_energy"], frameworks=("jax",), models=["baseline"])
    assert [u.claim.id for u in todo] == ["dp_loss", "dp_energy"]   # claim 2 rolls out claim 1's models
    first, second = W.unit_seconds(todo, tmp_path)
    assert first == pytest.approx(W.proxy_seconds(todo[0]) + W.EVAL_S) and first > W.EVAL_S
    assert second == W.EVAL_S
    u = todo[0]
    key = train_key(u.framework, u.spec(), u.protocol(), u.seed)
    (tmp_path / "trained" / "jax" / key).mkdir(parents=True)
    (tmp_path / "trained" / "jax" / key / "result.json").write_text("{}")
    assert W.unit_seconds(todo, tmp_path) == [W.EVAL_S, W.EVAL_S]
    group = group_key(u.framework, u.spec(), u.protocol(), u.seed)
    assert W.unit_seconds(todo, tmp_path / "elsewhere", {group: 123.0}) == [123.0 + W.EVAL_S, W.EVAL_S]


@pytest.mark.parametrize("jobs", [1, 2])
def test_the_bar_total_is_the_sum_of_the_estimates_and_it_ends_full(bars, tmp_path, jobs, monkeypatch):
    todo = runner.plan("smoke", claims=["dp_loss", "appendix_b"], frameworks=("jax",))
    seconds = [10.0 * (i + 1) for i in range(len(todo))]
    if jobs == 2:   # the chains answered at once, in this process
        monkeypatch.setattr(executor, "_Workers", inline_workers())
    executor.run_units(todo, tmp_path, "smoke", progress=False, jobs=jobs, seconds=seconds)
    bar = _outer(bars)
    assert bar.total == sum(seconds) and bar.n == pytest.approx(sum(seconds))


def test_a_run_weighs_its_units_by_their_estimates(bars, tmp_path):
    runner.run(profile="smoke", out=tmp_path, claims=["dp_loss", "dp_energy"], frameworks=("jax",),
               models=["baseline"], progress=False)
    todo = runner.plan("smoke", claims=["dp_loss", "dp_energy"], frameworks=("jax",), models=["baseline"])
    assert _outer(bars).total == pytest.approx(sum(W.unit_seconds(todo, tmp_path)))
    assert _outer(bars).total > len(todo) * W.EVAL_S   # the training's estimate is in it, not a unit count


def test_work_in_flight_is_credited_as_its_wall_time_passes_at_most_its_estimate():
    """Two chains out at once on a fake clock: the bar reads their wall time so far (each at most its
    estimate) before either ends, and each one's whole estimate once it has."""
    now = [0.0]
    bar = Bars(total=150.0)
    credit = W.InFlight(bar, clock=lambda: now[0])
    credit.start("long", 100.0)
    credit.start("short", 50.0)
    now[0] = 10.0
    credit.tick()
    assert bar.n == pytest.approx(20.0)   # two workers at the estimate's pace: 2 estimated seconds a second
    now[0] = 70.0
    credit.tick()
    assert bar.n == pytest.approx(70.0 + 50.0)   # the short one over its estimate is held at it
    credit.end("short")
    assert bar.n == pytest.approx(120.0)
    credit.end("long")   # ends early: the rest of its estimate at once
    assert bar.n == pytest.approx(150.0) and not credit.held
