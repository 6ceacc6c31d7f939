"""A registration made after a look at test-split numbers is named on the scorecard and given in full in the
appendix (`reports.sections_registration`)."""
from types import SimpleNamespace

from lagbench.reports import sections_registration as S
from lagbench.reports.document import Para, Section

LATE = "issue 80, disclosed: the protocol changed after a test-split check"


def _res(notes: dict):
    claims = [{"id": cid, "number": n} for n, cid in enumerate(notes, start=1)]
    verdicts = {cid: {"preregistration": {"protocol_hash": "h", "registered": note is not None, "frozen": "d",
                                          "note": note or "", "registrations": 1, "tuning": {}}}
                for cid, note in notes.items()}
    return SimpleNamespace(claims=claims, verdicts=verdicts, run={"profile": "quick"}, verdict_profile="quick")


def test_a_late_registration_is_named_on_the_scorecard_and_in_full_in_the_appendix():
    res = _res({"a": LATE, "b": "chosen on the development split", "c": LATE, "d": None})
    assert S.disclosed(res) == [("1", LATE), ("3", LATE)]   # d: no registration matches it
    assert "Registered anew after a look at test-split numbers, disclosed: claims 1, 3." in S.summary(res)
    s = Section("t")
    S.add_to(s, res)
    paras = [x.text for x in s.blocks if isinstance(x, Para)]
    assert paras == [f"Claims 1, 3: registered anew after a look at test-split numbers (disclosed): {LATE}."]


def test_no_late_registration_no_word_of_one():
    res = _res({"a": "chosen on the development split"})
    assert S.disclosed(res) == [] and "disclosed" not in S.summary(res)
