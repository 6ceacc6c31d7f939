"""A user's model in the suite's claims: `lagbench run --add-model NAME=module:factory` (`models.user`).

`parse(values) -> [Added]`: each "NAME=module:factory" (or "NAME=path/file.py:factory"), or a bare NAME that
an installed package declares in the entry point group `lagbench.models` (NAME = "module:factory"), the
factory imported and the file that defines it hashed; a ValueError naming the option and the value otherwise.
`entries(claim, added, profile) -> [ModelEntry]`: the model's entries in `claim`. It enters a claim whose
evaluation scores q-double-dot (held-out error, energy rollouts), once per system the claim's paper models
run on: it stands in for the first model the claim's parts read that trains on q-double-dot from (q, qdot)
alone (a Hamiltonian module: on the time derivative of (q, p), where the paper's HNN does), on that model's
data and with its protocol and budget as they run (`claims.resolved`: the adopted tuning where it has one).
Its label is NAME, or NAME_<system> where the claim has several systems. It runs in its own framework
(PyTorch for a torch.nn.Module, JAX for an equinox Module), is judged by the claim's bar and tables, and no
part or verdict reads it: an extra model beside the claim.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from lagbench.models.spec import USER_KIND
from lagbench.replication.claims.base import ModelEntry

SCORES_QDDOT = ("heldout", "energy_rollout", "heldout_trajectories")   # evaluations a q-double-dot model fits
NAME = re.compile(r"[A-Za-z][A-Za-z0-9-]{0,31}")


@dataclass(frozen=True)
class Added:
    name: str
    ref: str
    source: str      # sha256 (16 hex) of the file that defines the factory
    framework: str   # "torch" (a torch.nn.Module) or "jax" (an equinox Module: the factory takes a key)
    returns: str = "acceleration"   # or "lagrangian", "hamiltonian" (`models.user.returns`)


def parse(values, suite_labels=()) -> list[Added]:
    from lagbench.models.user import factory_source, framework_of, returns_of

    out = []
    for v in values or ():
        name, sep, ref = str(v).partition("=")
        if not sep and NAME.fullmatch(name):
            ref = installed(name)
        elif not sep or not ref:
            ref = ""
        if not NAME.fullmatch(name) or not ref:
            raise ValueError(f"--add-model {v}: give NAME=module:factory, NAME a letter then letters, digits "
                             f"or '-' (at most 32)")
        if name in suite_labels or name in {a.name for a in out}:
            raise ValueError(f"--add-model {v}: the name {name!r} is taken; choose another")
        out.append(Added(name, ref, factory_source(ref), framework_of(ref), returns_of(ref)))
    return out


GROUP = "lagbench.models"


def installed(name: str) -> str:
    """The "module:factory" an installed package declares for `name` in the entry point group GROUP."""
    from importlib.metadata import entry_points

    found = [ep.value for ep in entry_points(group=GROUP) if ep.name == name]
    if not found:
        names = sorted({ep.name for ep in entry_points(group=GROUP)})
        raise ValueError(f"--add-model {name}: no installed package declares it in the entry point group {GROUP} "
                         f"({'installed: ' + ', '.join(names) if names else 'none installed'}); or give "
                         f"NAME=module:factory")
    return found[0]


def _stand_in(model, task: str) -> bool:
    """Whether a model as it runs (`claims.resolved.RunModel`) is one a user's model of `task` stands in for."""
    return (model.train and model.protocol.task == task and not model.spec.get("extra_inputs")
            and model.spec.get("kind") != "lgn")


def entries(claim, added: Added, profile: str) -> list[ModelEntry]:
    from lagbench.replication.claims.resolved import resolved

    if claim.evaluate not in SCORES_QDDOT:
        return []
    run = resolved(claim, profile)
    read = [m for m in dict.fromkeys(m for part in claim.parts for m in part.reads) if m in run.labels]
    by_recipe = {}
    for label in read:
        model = run.model(label)
        if _stand_in(model, "hamiltonian" if added.returns == "hamiltonian" else "acceleration"):
            by_recipe.setdefault(model.protocol.data.recipe, model.entry)
    several = len(by_recipe) > 1
    out = []
    for recipe, template in by_recipe.items():
        label = f"{added.name}_{recipe.removesuffix('_iid')}" if several else added.name
        out.append(ModelEntry(label, {"kind": USER_KIND, "factory": added.ref, "factory_source": added.source},
                              hidden=(1,), overrides=template.overrides, profiles=template.profiles))
    return out


def framework(entry: ModelEntry) -> str:
    """The framework a user's entry runs in."""
    from lagbench.models.user import framework_of

    return framework_of(entry.spec["factory"])
