"""The seconds each worker group of the default test run took (`conftest.py`'s `worker_group`), from a run's JUnit
XML: what the run's scheduler reads to hand out the longest groups first, so that neither pytest-xdist worker is
left with a long file at the end while the other idles.

    python tests/timing/group_seconds.py JUNIT_XML > tests/timing/group_seconds.json

The JUnit XML comes from the README's test command with `--junitxml=FILE` added. A test's time there counts its
setup (module and session fixtures built for it) and teardown. Only the order matters, so a run on a loaded
machine serves; a group missing from the table (a new file) is placed as the table's median
(`conftest.longest_first`).
"""
import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def nodeid_path(classname: str, file: str | None) -> str:
    """The test file of a JUnit test case, as a node id's path (tests/.../test_x.py)."""
    if file:
        return file
    parts = classname.split(".")
    for k in range(len(parts), 0, -1):    # a class inside the module adds trailing parts
        path = "/".join(parts[:k]) + ".py"
        if (ROOT / path).is_file():
            return path
    return "/".join(parts) + ".py"


def group_seconds(junit: Path, worker_group) -> dict:
    seconds: dict[str, float] = {}
    for case in ET.parse(junit).getroot().iter("testcase"):
        group = worker_group(nodeid_path(case.get("classname", ""), case.get("file")))
        seconds[group] = seconds.get(group, 0.0) + float(case.get("time") or 0.0)
    return {g: round(s, 1) for g, s in sorted(seconds.items(), key=lambda kv: -kv[1])}


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    import conftest

    json.dump(group_seconds(Path(sys.argv[1]), conftest.worker_group), sys.stdout, indent=1)
    sys.stdout.write("\n")
