"""How the command line ends on an error: a user's error is one line and exit 2 (with -v, the traceback as
well); an exception the suite did not mean to raise is a bug: one line saying how to report it, exit 1, and its
traceback with -v."""
import pytest

from lagbench import cli


def _failing(monkeypatch, error):
    def fail(args):
        raise error
    real = cli.build_parser

    def parser():
        p = real()
        for action in p._subparsers._group_actions:
            for sub in action.choices.values():
                sub.set_defaults(func=fail)
        return p
    monkeypatch.setattr(cli, "build_parser", parser)


@pytest.mark.parametrize("error", [TypeError("unsupported operand"), KeyError("lr"), AttributeError("no x")])
def test_an_internal_bug_says_how_to_report_it(monkeypatch, capsys, error):
    _failing(monkeypatch, error)
    assert cli.main(["list"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"lagbench: internal error: {type(error).__name__}")
    assert "please report it" in err and "rerun with -v" in err and "Traceback" not in err


def test_with_verbose_an_internal_bug_prints_its_traceback(monkeypatch, capsys):
    _failing(monkeypatch, TypeError("unsupported operand"))
    assert cli.main(["-v", "list"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("Traceback (most recent call last)") and "def fail" not in err and "raise error" in err
    assert err.rstrip().splitlines()[-1].startswith("lagbench: internal error: TypeError: unsupported operand")


def test_a_users_error_stays_one_line_and_verbose_adds_the_traceback(monkeypatch, capsys):
    _failing(monkeypatch, ValueError("--seeds 0: give a positive count"))
    assert cli.main(["list"]) == 2
    assert capsys.readouterr().err == "lagbench: error: --seeds 0: give a positive count\n"
    assert cli.main(["-v", "list"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" in err and err.endswith("lagbench: error: --seeds 0: give a positive count\n")
    _failing(monkeypatch, KeyError("unknown claim 'x'; valid: dp_loss"))
    assert cli.main(["list"]) == 2
    assert capsys.readouterr().err == "lagbench: error: unknown claim 'x'; valid: dp_loss\n"

