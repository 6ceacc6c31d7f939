"""The kinds (`models.kinds`): the capability table as the one list of what each kind can do, each kind's record
of its own fields, and the flat form every key is built from (`ModelSpec.to_dict` / `from_dict`)."""
import dataclasses
import json

import pytest

from lagbench.models import KINDS, ModelSpec, param_shapes
from lagbench.models.kinds import FLAT_DEFAULTS, HOLDERS, USER_KIND, Delan, Hnn, Lgn, Lnn, User, capability
from lagbench.models.spec import COMMON, FLAT_KEYS, WHEN_SET

# a valid value other than the default for each own field, by flat name
OTHER = {"formulation": "paper", "delan_eps": 0.5, "delan_diag_offset": 1.0, "lgn_radius": 2, "lorentz_factor": True,
         "dissipation": True, "scale_q_before_grad": True, "even_velocity": True, "factory": "mine:make",
         "factory_source": "0" * 16}
ALL_KINDS = (*KINDS, USER_KIND)


def _spec(kind, **kw):
    base = {"factory": "mine:make"} if kind == USER_KIND else {}
    scale = {"input_scale": (1.0,) * 4} if kw.get("scale_q_before_grad") else {}
    return ModelSpec(kind=kind, dof=2, hidden=(8,), **{**base, **scale, **kw})


def test_the_flat_form_is_the_common_fields_and_every_kinds_own_fields():
    assert set(FLAT_KEYS) == set(COMMON) | set(FLAT_DEFAULTS) and len(FLAT_KEYS) == len(set(FLAT_KEYS))
    assert set(OTHER) == set(FLAT_DEFAULTS) and set(WHEN_SET) <= set(FLAT_KEYS)
    # the fields two kinds share have one default (the flat form writes one value for the kinds without them)
    assert FLAT_DEFAULTS["formulation"] == Lnn().formulation == Lgn().formulation == "fast"
    user = _spec(USER_KIND, factory_source="0" * 16).to_dict()
    assert (user["factory"], user["factory_source"], user["lgn_radius"]) == ("mine:make", "0" * 16, 1)
    assert "factory" not in _spec("lnn").to_dict()


@pytest.mark.parametrize("kind", ALL_KINDS)
def test_a_kind_refuses_another_kinds_field_and_takes_it_at_its_default(kind):
    for key, holders in HOLDERS.items():
        if kind in holders:
            assert _spec(kind, **{key: OTHER[key]}).to_dict()[key] == OTHER[key]
            continue
        assert _spec(kind, **{key: FLAT_DEFAULTS[key]}) == _spec(kind)   # every flat form writes it at its default
        many = "s" if len(holders) > 1 else ""
        with pytest.raises(ValueError, match=rf"^{key} is for kind{many} {', '.join(holders)}, not '{kind}' \(the "
                                             rf"own fields of '{kind}': "):
            _spec(kind, **{key: OTHER[key]})


def test_the_capability_columns_are_what_the_spec_checks():
    """Which kinds may learn a dissipation, see the Lorentz factor or periodic coordinates: read from the
    table (the records' fields), and the spec and the parameter layout follow it."""
    assert [k for k in KINDS if capability(k).dissipation] == ["lnn", "hnn", "delan"]
    assert [k for k in KINDS if capability(k).lorentz_factor] == ["lnn", "hnn"]
    assert [k for k in KINDS if capability(k).periodic] == ["baseline", "lnn", "hnn", "delan"]
    for kind in KINDS:
        cap = capability(kind)
        if cap.dissipation:
            assert param_shapes(_spec(kind, dissipation=True))["dissipation.raw"] == (2,)
        if cap.periodic:
            assert _spec(kind, periodic=(0,)).q_width() == 3
        else:
            with pytest.raises(ValueError, match=f"periodic is for kinds baseline, lnn, hnn, delan, not '{kind}'"):
                _spec(kind, periodic=(0,))
        # mlp_sizes reads the table: a trunk without a head (delan), one output, or n_out
        sizes = _spec(kind).mlp_sizes()
        assert len(sizes) == (2 if cap.mlp_head else 1) + 1
        assert not cap.mlp_head or sizes[-1] == (1 if cap.scalar_output else 2)


def test_a_record_checks_its_own_fields():
    for make, match in ((lambda: Lnn(formulation="banded"), "unknown lnn formulation 'banded'; valid: fast, paper"),
                        (lambda: Lnn(formulation="paper", dissipation=True), "fast formulation, not 'paper'"),
                        (lambda: Lnn(lorentz_factor=1), "lorentz_factor must be True or False, got 1"),
                        (lambda: Hnn(dissipation="yes"), "dissipation must be True or False"),
                        (lambda: Lgn(radius=2.0), r"lgn_radius must be an integer >= 1, got 2\.0"),
                        (lambda: Lgn(formulation="sparse"), "unknown lgn formulation 'sparse'"),
                        (lambda: Delan(eps=-0.1), "delan_eps must be a finite number >= 0, got -0.1"),
                        (lambda: Delan(diag_offset=float("nan")), "delan_diag_offset must be a finite number"),
                        (lambda: User(), "kind 'user' needs a factory"),
                        (lambda: ModelSpec(kind="lnn", dof=2, own=Hnn()), "kind 'lnn' holds its own fields in a Lnn")):
        with pytest.raises(ValueError, match=match):
            make()
    assert Lgn(formulation="dense", radius=3) == _spec("lgn", formulation="dense", lgn_radius=3).own


def test_a_spec_changes_an_own_field_by_its_flat_name():
    spec = _spec("lnn", extra_inputs=1)
    paper = dataclasses.replace(spec, formulation="paper")
    assert paper.own == Lnn(formulation="paper") and paper.extra_inputs == 1 and spec.own == Lnn()
    assert dataclasses.replace(spec, own=Lnn(lorentz_factor=True)).mlp_sizes()[0] == 7
    with pytest.raises(ValueError, match="lgn_radius is for kind lgn, not 'lnn'"):
        dataclasses.replace(spec, lgn_radius=2)


def _claim_specs():
    from lagbench.replication.claims import CLAIMS
    from lagbench.replication.claims.base import PROFILES
    from lagbench.replication.run.units import Unit

    return {f"{cid}/{profile}/{m.label}": Unit(claim, m, "jax", 0, profile).spec()
            for cid, claim in CLAIMS.items() for profile in PROFILES for m in claim.models if m.runs_in(profile)}


def test_every_claims_spec_round_trips_through_its_flat_form():
    specs = _claim_specs()
    assert {s.kind for s in specs.values()} == set(KINDS)
    for name, spec in specs.items():
        d = spec.to_dict()
        back = ModelSpec.from_dict(json.loads(json.dumps(d)))
        assert back == spec and hash(back) == hash(spec), name
        assert back.to_dict() == d and list(d) == [k for k in FLAT_KEYS if k in d], name
        assert {k for k in FLAT_KEYS if k not in d} <= set(WHEN_SET), name
