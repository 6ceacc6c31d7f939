"""`lagbench fit`'s options are one record (`replication.fit.options`): the command line's defaults are the
function's, every option is checked by its own rule, and an unknown keyword is refused."""
import pytest

from replication.cli import build_parser
from replication.fit import options as fit_options
from replication.fit.task import fit


def test_the_command_lines_defaults_are_the_functions():
    args = build_parser().parse_args(["fit", "--data", "d.csv", "--model", "lnn"])
    given = fit_options.from_args(args)
    assert set(given) == set(fit_options.BY_NAME)
    assert vars(fit_options.resolve(given)) == vars(fit_options.resolve({"model": "lnn"}))


def test_every_flag_is_in_the_help_with_its_default(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["fit", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    for o in fit_options.OPTIONS:
        assert o.cli in out
        if not o.switch and o.default is not None and not o.required:
            shown = o.text if o.parse is not None else o.default
            assert f"(default: {shown})" in out, o.name


@pytest.mark.parametrize("name, value", [("steps", 0), ("lr", float("inf")), ("loss", "huber"), ("hidden", (8, 0)),
                                         ("horizon", -1.0), ("lr_min_ratio", 2.0), ("input_scale", (1.0, -1.0))])
def test_each_option_is_checked_by_its_own_rule(name, value):
    flag = fit_options.BY_NAME[name].cli
    with pytest.raises(ValueError, match=f"^{flag}: "):
        fit_options.check({name: value})


def test_an_unknown_keyword_is_refused(tmp_path):
    with pytest.raises(TypeError, match="unknown options stepz"):
        fit(tmp_path / "d.csv", out=tmp_path / "o", stepz=3)
