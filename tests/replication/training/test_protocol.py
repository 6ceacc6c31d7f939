"""The protocol record (`replication.training.protocol`): its records, its canonical form and key, and the
reading of the earlier forms (`replication.training.protocol_versions`) that older result folders hold."""
import json

import pytest

from lagbench.replication.training.protocol import (
    KEY_VERSION,
    Adam,
    Data,
    EarlyStop,
    Guard,
    Protocol,
    Scouting,
    Tracking,
)
from lagbench.replication.training.schedules import Constant, OneCycle, StepDecay

BASE = Protocol(data=Data("double_pendulum_iid", n_train=64), steps=10, batch=8, log_every=5)
FULL = BASE.replace(guard=Guard(clip=100.0, skip=10.0), tracking=Tracking(every=5),
                    scouting=Scouting(count=4, steps=6, batch=4, schedule=OneCycle(lr=3e-3, start=0.1), keep=2))


def test_the_canonical_form_round_trips_and_holds_every_field():
    for p in (BASE, FULL, BASE.replace(cohort=3), BASE.replace(schedule=StepDecay(lr=1e-2, every=3, gamma=0.5)),
              BASE.replace(schedule=Constant(lr=2e-3), optimiser=Adam(b2=0.99)),
              FULL.replace(early_stop=EarlyStop(every=5, patience=2))):
        d = p.to_dict()
        assert d["version"] == KEY_VERSION
        # no field dropped while off, but the parts no claim has (the claims' keys stay as they were)
        off = {n for n in ("early_stop", "trajectory_loss", "filter_loss") if getattr(p, n) is None}
        assert set(d) == {"version", *(f for f in p.__dataclass_fields__)} - off
        assert Protocol.from_dict(json.loads(json.dumps(d))) == p
    # a schedule holds only the values its shape uses
    assert set(BASE.replace(schedule=Constant(lr=1.0)).to_dict()["schedule"]) == {"kind", "lr"}


def test_one_number_one_key():
    """A real field takes 1 as 1.0: one protocol and one key. A count takes no float, not even 10.0 (the shared
    checks of `lagbench.validate`, as the model spec's)."""
    a = BASE.replace(l2=0, **{"schedule.lr": 1, "optimiser.eps": 1})
    assert a == BASE.replace(l2=0.0, **{"schedule.lr": 1.0, "optimiser.eps": 1.0})
    assert a.key() == BASE.replace(**{"schedule.lr": 1.0, "optimiser.eps": 1.0}).key()
    assert isinstance(a.l2, float) and isinstance(a.schedule.lr, float) and isinstance(a.optimiser.eps, float)
    for field in ("steps", "batch", "log_every", "data.n_train", "data.n_heldout", "scouting.steps", "tracking.every"):
        name = field.replace(".", " ") if "." in field else f"protocol {field}"
        with pytest.raises(ValueError, match=f"^{name} must be an integer >= 1, got 10.0$"):
            FULL.replace(**{field: 10.0})
    assert BASE.key() != BASE.replace(**{"schedule.lr": 2e-3}).key() and FULL.key() != BASE.key()
    assert BASE.key() != BASE.replace(**{"data.n_heldout": 11}).key()


def test_a_record_changes_by_its_dotted_name_only_when_on():
    p = FULL.replace(**{"scouting.schedule.lr": 1e-2, "guard.skip": 5.0, "data.n_train": 128})
    assert (p.scouting.schedule.lr, p.scouting.count, p.guard.skip, p.guard.clip) == (1e-2, 4, 5.0, 100.0)
    assert p.data.n_train == 128 and p.scouting.schedule.start == 0.1
    with pytest.raises(ValueError, match="has no guard"):
        BASE.replace(**{"guard.clip": 1.0})
    with pytest.raises(ValueError, match="cannot set scouting.rate: no such field"):
        FULL.replace(**{"scouting.rate": 1.0})
    with pytest.raises(ValueError, match="cannot set lr: no such field"):
        BASE.replace(lr=1.0)
    with pytest.raises(ValueError, match="cannot set schedule.every"):   # a one-cycle has no decay interval
        BASE.replace(**{"schedule.every": 3})


def test_records_are_checked():
    with pytest.raises(ValueError, match="tracking every 3 is not a multiple of log_every 5"):
        BASE.replace(tracking=Tracking(every=3))
    with pytest.raises(ValueError, match="scouting batch 65 exceeds"):
        BASE.replace(scouting=Scouting(count=2, steps=2, batch=65, schedule=OneCycle(lr=1e-3, start=0.2)))
    with pytest.raises(ValueError, match="tracking every"):
        Tracking(every=0)
    with pytest.raises(ValueError, match="protocol scouting must be a Scouting"):
        BASE.replace(scouting={"count": 2})
    with pytest.raises(ValueError, match="batch 8 exceeds the training pool n_train=4"):
        BASE.replace(**{"data.n_train": 4})
    with pytest.raises(ValueError, match="protocol data must be a record"):
        Protocol(data="double_pendulum_iid", steps=1, batch=1)
    with pytest.raises(ValueError, match="unknown coords"):
        Data("spring_iid", n_train=4, coords="xy")
    with pytest.raises(ValueError, match="scouting schedule must be a schedule record"):
        Scouting(count=2, steps=2, batch=2, schedule="onecycle")
    with pytest.raises(ValueError, match="Adam b2"):
        Adam(b2=1.0)


def test_a_version_2_dict_reads_as_the_same_protocol():
    """Version 2: data, optimiser and schedule flat; the scouting with its own peak and one-cycle start over
    the protocol's schedule shape."""
    v2 = {"version": 2, "data": "wave_iid", "steps": 10, "batch": 8, "n_train": 64, "n_heldout": 32,
          "system_params": [["n", 10]], "resample": False, "task": "acceleration", "coords": "qqdot", "loss": "l1",
          "lr": 3e-3, "schedule": "step", "lr_start": 0.3, "lr_min_ratio": 1e-4, "lr_step_every": 100,
          "lr_step_gamma": 0.1, "b1": 0.9, "b2": 0.999, "eps": 1e-8, "l2": 0.0, "guard": None,
          "scouting": {"count": 2, "steps": 5, "batch": 8, "lr": 1e-2, "lr_start": 0.3, "keep": None},
          "cohort": None, "tracking": None, "dtype": "float32", "log_every": 5}
    p = Protocol.from_dict(v2)
    assert p.data == Data("wave_iid", n_train=64, n_heldout=32, system_params=(("n", 10),))
    assert p.schedule == StepDecay(lr=3e-3, every=100, gamma=0.1)
    assert p.scouting.schedule == StepDecay(lr=1e-2, every=100, gamma=0.1)
    one = Protocol.from_dict({**v2, "schedule": "onecycle", "lr_start": 0.1})
    assert one.schedule == OneCycle(lr=3e-3, start=0.1) and one.scouting.schedule == OneCycle(lr=1e-2, start=0.3)


def test_a_version_1_dict_reads_as_the_same_protocol():
    """The flat form older result folders hold: 0 = off; a scout batch, rate or start of 0 = the protocol's;
    scout steps 0 = 5e5 samples at the scout batch; `eval` is dropped."""
    v1 = {"data": "double_pendulum_iid", "steps": 10, "batch": 8, "n_train": 64, "log_every": 5, "lr": 2e-3,
          "lr_start": 0.1, "grad_clip": 100.0, "spike_skip": 10.0, "scouts": 4, "scout_steps": 0, "scout_batch": 0,
          "scout_lr": 0.0, "scout_keep": 2, "track_every": 5, "cohort": 0, "eval": {}, "system_params": []}
    p = Protocol.from_dict(v1)
    assert p.guard == Guard(clip=100.0, skip=10.0) and p.tracking == Tracking(every=5) and p.cohort is None
    assert p.scouting == Scouting(count=4, steps=500_000 // 8, batch=8, schedule=OneCycle(lr=2e-3, start=0.1), keep=2)
    plain = Protocol.from_dict({k: v for k, v in v1.items() if not k.startswith(("scout", "grad", "spike", "track"))})
    assert plain == BASE.replace(schedule=OneCycle(lr=2e-3, start=0.1))
    with pytest.raises(ValueError, match="rollback"):
        Protocol.from_dict({**v1, "rollback": 2.5})
    with pytest.raises(ValueError, match="protocol version 9"):
        Protocol.from_dict({**FULL.to_dict(), "version": 9})
