"""The installed wheel puts one name at the top of site-packages, `lagbench`, so a user's own packages called
`models` and `systems` (common names in research code) stay theirs: built from a copy of the sources,
installed into a folder of its own, and run from a working folder that holds both, `--add-model` and
`--predict` import the user's modules while the suite runs from the wheel."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from test_import_cycles import FOLDERS

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ("pyproject.toml", "setup.py", "README.md", "LICENSE", *FOLDERS)

USER_MODELS = '''"""The user's own package `models`: an --add-model factory."""
import torch


class Net(torch.nn.Module):
    def __init__(self, dof):
        super().__init__()
        self.body = torch.nn.Sequential(torch.nn.Linear(2 * dof, 16), torch.nn.Tanh(), torch.nn.Linear(16, dof))

    def forward(self, q, qdot):
        return self.body(torch.cat([q, qdot], -1))


def make(dof):
    return Net(dof)
'''
USER_SYSTEMS = '''"""The user's own module `systems`: a --predict function, with the suite's systems beside it."""
from models import Net  # noqa: F401  (the user's package, not the suite's)

from lagbench import systems as suite


def exact(q, qdot):
    return suite.get("double_pendulum").acceleration(q, qdot, backend="numpy")
'''


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    src, site = tmp_path_factory.mktemp("src"), tmp_path_factory.mktemp("site")
    for name in SOURCES:
        p = ROOT / name
        if p.is_dir():
            shutil.copytree(p, src / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        else:
            shutil.copy2(p, src / name)
    wheels = tmp_path_factory.mktemp("wheels")
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "--no-input", "-q"]
    subprocess.run([*pip, "wheel", "--no-deps", "--no-build-isolation", "-w", str(wheels), str(src)], check=True,
                   capture_output=True)
    subprocess.run([*pip, "install", "--no-deps", "--target", str(site), *map(str, wheels.glob("*.whl"))],
                   check=True, capture_output=True)
    return site


def _run(site, cwd, *args, code=None):
    env = {**os.environ, "PYTHONPATH": str(site)}
    argv = ["-c", code] if code else ["-m", "lagbench", *args]
    return subprocess.run([sys.executable, *argv], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


def test_the_wheel_installs_only_lagbench(site, tmp_path):
    top = {p.name for p in site.iterdir() if p.name != "bin"}
    assert {n for n in top if not n.endswith(".dist-info")} == {"lagbench"}
    r = _run(site, tmp_path, code="import importlib.util as u, lagbench.models, lagbench.systems; "
                                  "print(u.find_spec('models'), u.find_spec('systems'), lagbench.models.__file__)")
    assert r.returncode == 0, r.stderr
    assert r.stdout.split()[:2] == ["None", "None"] and r.stdout.split()[2].startswith(str(site))


def test_users_models_and_systems_packages_stay_the_users(site, tmp_path):
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "__init__.py").write_text(USER_MODELS)
    (tmp_path / "systems.py").write_text(USER_SYSTEMS)
    r = _run(site, tmp_path, "run", "--profile", "smoke", "--claims", "dp_loss", "--frameworks", "torch", "--n-seeds", "1",
             "--add-model", "mine=models:make", "--out", "results/mine", "--quiet")
    assert r.returncode == 0, r.stderr[-3000:]
    units = tmp_path / "results" / "mine" / "units" / "dp_loss" / "torch"
    assert sorted(p.name for p in units.iterdir()) == ["baseline", "lnn", "mine"]
    assert '"status": "ok"' in next((units / "mine").glob("seed*/result.json")).read_text()
    r = _run(site, tmp_path, "evaluate", "--predict", "systems:exact", "--system", "double_pendulum", "--profile",
             "smoke", "--out", "results/mine")
    assert r.returncode == 0, r.stderr[-3000:]
    assert "heldout_l1 0," in r.stdout + r.stderr
