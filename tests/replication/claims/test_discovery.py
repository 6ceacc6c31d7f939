"""Claims are discovered (`replication.claims.discover`): a module of the package whose top level writes
`CLAIM = Claim(...)` is a claim, with no list to edit; the claims are ordered by number and held as written
(what runs is `claims.resolved`); a module of shared settings is not imported to look for one."""
import sys
import textwrap

import pytest

from lagbench.replication import claims as package
from lagbench.replication.claims import CLAIMS, discover

NEW = "lagbench.replication.claims.extra_claim"


def _add_module(folder, name: str, number: int) -> None:
    (folder / f"{name}.py").write_text(textwrap.dedent(f'''\
        """A claim written the way every claim file is: its record at the top level."""
        from lagbench.replication.claims import appendix_b
        from lagbench.replication.claims.base import Claim

        CLAIM = Claim(**{{**appendix_b.CLAIM.__dict__, "id": "{name}", "number": {number}}})
        '''))


@pytest.fixture
def package_with(tmp_path, monkeypatch):
    """The claims package with a folder of extra modules on its path (removed again after the test)."""
    monkeypatch.setattr(package, "__path__", [*package.__path__, str(tmp_path)])
    for name in ("extra_claim", "extra_settings"):
        monkeypatch.delitem(sys.modules, f"{package.__name__}.{name}", raising=False)
    (tmp_path / "extra_settings.py").write_text("SHARED = 1 / 0   # imported, it would fail\n")
    return tmp_path


def test_a_new_claim_file_in_the_package_is_picked_up(package_with):
    _add_module(package_with, "extra_claim", 0)
    found = discover(package.__name__, package.__path__)
    assert list(found) == ["extra_claim", *CLAIMS]   # number 0 goes first, the others keep their order
    assert found["extra_claim"].models == CLAIMS["appendix_b"].models and NEW in sys.modules
    assert f"{package.__name__}.extra_settings" not in sys.modules   # no CLAIM written there: not imported


def test_two_claims_with_one_number_are_refused(package_with):
    _add_module(package_with, "extra_claim", CLAIMS["dp_loss"].number)
    with pytest.raises(ValueError, match="share a number: 1"):
        discover(package.__name__, package.__path__)


def test_the_claims_are_their_files_records_in_number_order():
    """CLAIMS holds each module's own `CLAIM`, unchanged (nothing is applied to it at import), by number."""
    assert [c.number for c in CLAIMS.values()] == sorted(c.number for c in CLAIMS.values())
    for cid, claim in CLAIMS.items():
        module = next(m for m in list(sys.modules.values()) if getattr(m, "CLAIM", None) is claim
                      and m.__name__.startswith(package.__name__ + "."))
        assert module.__name__.startswith(package.__name__ + ".") and claim.id == cid
