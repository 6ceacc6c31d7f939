"""Which loss a fit trains on (`--loss-target`): acceleration, trajectory, filtered, or auto (the default).

`choose(mode, kind, task, recording, given) -> record` ({"mode", "chosen", "why"}): `auto` is "filtered" for the
kinds in `FILTERED` (DeLaN) on a trajectory file whose q-double-dot the fit estimates from q (`given`: the
derivative columns the file has, none), where a registered study measured it (docs/lab/recording_defaults.md,
"The study: the filtered acceleration loss": on simulated double-pendulum recordings at 0.5 degree of noise
DeLaN read the friction within 3.4 % on the median seed against 16 % under the acceleration loss, with 0.61 x
its rollout error; the LNN, at the acceleration loss's work a step, and the baseline rolled out worse under it);
"acceleration" otherwise. `describe(record)` in words for the console and the report; `auto_departed(record)`:
whether `auto` chose another loss than the acceleration loss (what the console and eval_config report).
"""
from __future__ import annotations

MODES = ("auto", "acceleration", "trajectory", "filtered")
FILTERED = {("delan", "acceleration")}
WHERE = "DeLaN on a trajectory file whose q-double-dot is estimated from q (docs/lab/recording_defaults.md)"


def choose(mode: str, kind: str, task: str, recording: bool, given) -> dict:
    if mode != "auto":
        return {"mode": mode, "chosen": mode, "why": "as given"}
    if (kind, task) not in FILTERED:
        return {"mode": mode, "chosen": "acceleration", "why": "filtered only for " + WHERE}
    if not recording or given:
        return {"mode": mode, "chosen": "acceleration",
                "why": ("not a trajectory file" if not recording else f"the file gives {' and '.join(given)}")
                + ": filtered only for " + WHERE}
    return {"mode": mode, "chosen": "filtered", "why": WHERE}


def describe(record: dict) -> str:
    return f"{record.get('chosen')} (--loss-target {record.get('mode')}): {record.get('why')}"


def auto_departed(record: dict) -> bool:
    return record.get("mode") == "auto" and record.get("chosen") != "acceleration"
