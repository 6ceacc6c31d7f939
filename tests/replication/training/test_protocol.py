"""The protocol record (`replication.training.protocol`): its parts, its canonical form and key, and the
reading of version-1 (flat) protocol dicts from older result folders."""
import json

import pytest

from replication.training.protocol import KEY_VERSION, Guard, Protocol, Scouting, Tracking

BASE = Protocol(data="double_pendulum_iid", steps=10, batch=8, n_train=64, log_every=5)
FULL = BASE.replace(guard=Guard(clip=100.0, skip=10.0), tracking=Tracking(every=5),
                    scouting=Scouting(count=4, steps=6, batch=4, lr=3e-3, lr_start=0.1, keep=2))


def test_the_canonical_form_round_trips_and_holds_every_field():
    for p in (BASE, FULL, BASE.replace(cohort=3)):
        d = p.to_dict()
        assert d["version"] == KEY_VERSION
        assert set(d) == {"version", *(f for f in p.__dataclass_fields__)}   # no field dropped while off
        assert Protocol.from_dict(json.loads(json.dumps(d))) == p


def test_one_number_one_key():
    """1 and 1.0 (or an integral float from JSON) give one protocol and one key."""
    a = BASE.replace(lr=1, l2=0, steps=10.0)
    assert a == BASE.replace(lr=1.0) and a.key() == BASE.replace(lr=1.0).key()
    assert isinstance(a.steps, int) and isinstance(a.lr, float)
    assert BASE.key() != BASE.replace(lr=2e-3).key() and FULL.key() != BASE.key()


def test_a_part_changes_by_its_dotted_name_only_when_on():
    p = FULL.replace(**{"scouting.lr": 1e-2, "guard.skip": 5.0})
    assert (p.scouting.lr, p.scouting.count, p.guard.skip, p.guard.clip) == (1e-2, 4, 5.0, 100.0)
    with pytest.raises(ValueError, match="has no guard"):
        BASE.replace(**{"guard.clip": 1.0})
    with pytest.raises(TypeError):
        FULL.replace(**{"scouting.rate": 1.0})


def test_parts_are_checked():
    with pytest.raises(ValueError, match="tracking every 3 is not a multiple of log_every 5"):
        BASE.replace(tracking=Tracking(every=3))
    with pytest.raises(ValueError, match="scouting batch 65 exceeds"):
        BASE.replace(scouting=Scouting(count=2, steps=2, batch=65, lr=1e-3, lr_start=0.2))
    with pytest.raises(ValueError, match="tracking every"):
        Tracking(every=0)
    with pytest.raises(ValueError, match="protocol scouting must be a Scouting"):
        BASE.replace(scouting={"count": 2})


def test_a_version_1_dict_reads_as_the_same_protocol():
    """The flat form older result folders hold: 0 = off; a scout batch, rate or start of 0 = the protocol's;
    scout steps 0 = 5e5 samples at the scout batch; `eval` is dropped."""
    v1 = {"data": "double_pendulum_iid", "steps": 10, "batch": 8, "n_train": 64, "log_every": 5, "lr": 2e-3,
          "lr_start": 0.1, "grad_clip": 100.0, "spike_skip": 10.0, "scouts": 4, "scout_steps": 0, "scout_batch": 0,
          "scout_lr": 0.0, "scout_keep": 2, "track_every": 5, "cohort": 0, "eval": {}, "system_params": []}
    p = Protocol.from_dict(v1)
    assert p.guard == Guard(clip=100.0, skip=10.0) and p.tracking == Tracking(every=5) and p.cohort is None
    assert p.scouting == Scouting(count=4, steps=500_000 // 8, batch=8, lr=2e-3, lr_start=0.1, keep=2)
    plain = Protocol.from_dict({k: v for k, v in v1.items() if not k.startswith(("scout", "grad", "spike", "track"))})
    assert plain == BASE.replace(lr=2e-3, lr_start=0.1)
    with pytest.raises(ValueError, match="rollback"):
        Protocol.from_dict({**v1, "rollback": 2.5})
    with pytest.raises(ValueError, match="protocol version 9"):
        Protocol.from_dict({**FULL.to_dict(), "version": 9})
