"""The example of docs/your_model.md, run end to end as written: its model file and its commands, in a fresh
folder (the README shows the same commands). The user's model trains in the double-pendulum claims beside the
paper's models (PyTorch only), is judged by the claim's bar, and no part reads it; the exact acceleration
scores at the chaos floor and the zero function as the null."""
import json
import re
import shlex
from pathlib import Path

import pytest

from lagbench.cli import main

ROOT = Path(__file__).resolve().parents[3]
DOC = ROOT / "docs" / "your_model.md"
MARKER = "<!-- your-model example: tests/replication/run/test_your_model_example.py runs this file and these commands -->"


def _commands(block: str) -> list[list[str]]:
    return [shlex.split(line) for line in block.splitlines() if line.startswith("lagbench ")]


def _example():
    text = DOC.read_text(encoding="utf-8")
    assert MARKER in text, "docs/your_model.md lost the example's marker"
    section = text[text.index(MARKER):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    commands = re.search(r"```bash\n(.*?)```", section, re.S).group(1)
    return code, _commands(commands)


def test_the_readme_shows_the_commands_this_test_runs():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = [_commands(b) for b in re.findall(r"```bash\n(.*?)```", readme, re.S)]
    assert _example()[1] in blocks, "the README's your-model commands differ from docs/your_model.md's example"


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    folder = tmp_path_factory.mktemp("your_model")
    code, commands = _example()
    (folder / "my_model.py").write_text(code, encoding="utf-8")
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(folder)
        codes = [main(argv[1:]) for argv in commands]
    return folder, commands, codes


def test_the_readme_commands_run_and_name_the_model_file(ran):
    _, commands, codes = ran
    assert [c[1] for c in commands] == ["run", "evaluate", "evaluate", "table", "report"]
    assert codes == [0] * len(commands)


def test_the_users_model_trains_beside_the_papers_in_pytorch_and_decides_nothing(ran):
    folder, _, _ = ran
    res = folder / "results" / "mine"
    for claim in ("dp_loss", "dp_energy"):
        assert sorted(p.name for p in (res / "units" / claim / "torch").iterdir()) == ["baseline", "lnn", "mine"]
        assert not (res / "units" / claim / "jax" / "mine").exists()
    r = json.loads(next((res / "units" / "dp_loss" / "torch" / "mine").glob("seed*/result.json")).read_text())
    assert r["status"] == "ok" and r["model_spec"]["kind"] == "user"
    assert r["model_spec"]["factory"] == "my_model.py:make" and len(r["model_spec"]["factory_source"]) == 16
    v = json.loads((res / "summary" / "verdicts.json").read_text())["claims"]
    entry = v["dp_loss"] if isinstance(v, dict) else next(c for c in v if c.get("id") == "dp_loss")
    assert "mine" in entry["competence"]["torch"]   # judged by the claim's bar
    assert "mine" not in json.dumps(entry["parts"])   # read by no part
    report = (folder / "report" / "mine" / "REPORT.md").read_text()
    assert report.count("| mine (added: --add-model; no verdict reads it) |") == 2   # claims 1 and 2 tables


def test_the_exact_acceleration_scores_at_the_chaos_floor_and_zero_as_the_null(ran):
    folder, _, _ = ran
    base = folder / "results" / "mine" / "predict" / "double_pendulum"
    exact = json.loads((base / "exact" / "result.json").read_text())["metrics"]
    zero = json.loads((base / "zero" / "result.json").read_text())["metrics"]
    assert exact["heldout_l1"] == 0.0 and exact["vpt_s"] >= 0.5 * exact["chaos_floor_vpt_s"]
    assert zero["null_heldout_l1"] <= zero["heldout_l1"] <= 1.01 * zero["null_heldout_l1"]
    assert zero["vpt_s"] < 0.25 * exact["vpt_s"]   # smoke's short horizon: the exact function follows it whole


def test_the_table_compares_like_with_like(ran):
    """The functions are scored under the profile the models trained in: one profile in the table."""
    import pandas as pd

    folder, _, _ = ran
    table = pd.read_csv(folder / "results" / "mine" / "summary" / "systems.csv")
    assert set(table["profile"]) == {"smoke"}
