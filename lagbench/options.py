"""One meaning per option name across `lagbench`'s commands, and the old spellings read for one release (the
ground floor: imports nothing of the suite).

The names every command reads alike:
  --frameworks  comma-separated jax, torch (`frameworks`); a command that runs in one framework takes exactly
                one (`one_framework`, a check).
  --seeds       seeds themselves, comma- or space-separated (`seeds`); --n-seeds a count of seeds.
  --out         what a command writes: a folder (a .csv file for `simulate`).

Old spellings. `add(parser, new, *old, why=..., **kwargs)` adds the option `new` with its old spellings hidden
from the help; any spelling stores into the one value. An old one prints `NOTICE` on stderr, once per parse:
"lagbench: note: --framework is now --frameworks; the old spelling is read until the next release". Two
spellings of one option in one command line are refused (argparse's usage and one line, exit 2).
`respell(parser, old, new)` does the same to an option another module added as `old`. `add_seeds(parser)`:
the --seeds and --n-seeds of `run` and `tune`, where --seeds was a count: a lone number after --seeds,
without a comma, is still read as --n-seeds, with the notice. `renamed(...)` prints the same notice for an
old spelling a command resolves itself (`lagbench fit`'s options).

Checks. `check(parser, dest, fn)` registers fn(value) -> value for a command's option; `run_checks(args)`
(called by `lagbench.cli.main` before the command) runs them, so a bad value is one line naming the option
(a ValueError), as the commands' own checks are.

Help. `show_defaults(parser)`: every option's help ends with "(default: X)", the one way a default is
written, unless it writes one itself; flags, and options whose help starts with "required", have none.
"""
from __future__ import annotations

import argparse
import sys

FRAMEWORKS = ("jax", "torch")
NOTICE = "lagbench: note: {old} is now {new}; the old spelling is read until the next release"
_SPELLED = "_spelled"    # on a parsed namespace: {dest: the spelling given}
_NOTICED = "_noticed"    # on a parsed namespace: the old spellings noticed
_CHECKS = "_checks"      # a command's default: ((dest, check), ...)
_SHOWN: set = set()      # the notices `renamed` printed in this command


def notice(old: str, new: str, why: str = "", namespace=None) -> None:
    """The notice of an old spelling on stderr, once per parse of a command line (`namespace`) or, without
    one, once per command (`forget_notices` starts a command)."""
    seen = _SHOWN if namespace is None else getattr(namespace, _NOTICED, set())
    if old in seen:
        return
    seen.add(old)
    if namespace is not None:
        setattr(namespace, _NOTICED, seen)
    print(NOTICE.format(old=old, new=new) + (f" ({why})" if why else ""), file=sys.stderr)


def forget_notices() -> None:
    _SHOWN.clear()


def renamed(command: str, new, old, default, new_flag: str, old_flag: str, why: str = ""):
    """The value of an option of `command`, given as `new_flag` (value `new`, `default` when not given) or as
    its old spelling `old_flag` (value `old`, None when not given): the old one with the notice (`why` says
    what the old name means elsewhere); a ValueError when both are given."""
    if old is None:
        return new
    if new != default:
        raise ValueError(f"{old_flag}: give it once, as {new_flag} ({old_flag} is its old spelling in `{command}`)")
    notice(old_flag, new_flag, why)
    return old


def _record(parser, namespace, dest: str, spelling: str, new: str) -> None:
    given = dict(getattr(namespace, _SPELLED, None) or {})
    if given.get(dest, spelling) != spelling:
        parser.error(f"{given[dest]} and {spelling} are one option; give it once, as {new}")
    given[dest] = spelling
    setattr(namespace, _SPELLED, given)


class _Spelling(argparse.Action):
    """Stores the value given under one spelling of an option; `new` is its current one, any other an old one
    (read with the notice)."""

    def __init__(self, option_strings, dest, new: str = "", why: str = "", **kwargs):
        super().__init__(option_strings, dest, **kwargs)
        self.new, self.why = new or option_strings[0], why

    def __call__(self, parser, namespace, values, option_string=None):
        _record(parser, namespace, self.dest, option_string, self.new)
        if option_string != self.new:
            notice(option_string, self.new, self.why, namespace)
        setattr(namespace, self.dest, values)


def add(parser, new: str, *old: str, why: str = "", **kwargs) -> argparse.Action:
    """The option `new` (argparse's keywords, a value stored as given) and its old spellings `old`, hidden."""
    kwargs.setdefault("metavar", new.lstrip("-").upper().replace("-", "_"))
    action = parser.add_argument(new, action=_Spelling, new=new, why=why, **kwargs)
    hidden = {k: v for k, v in kwargs.items() if k not in ("help", "required", "default")}
    for spelling in old:
        parser.add_argument(spelling, action=_Spelling, new=new, why=why, **{**hidden, "dest": action.dest},
                            default=argparse.SUPPRESS, help=argparse.SUPPRESS)
    return action


def respell(parser, old: str, new: str, why: str = "", **changes) -> argparse.Action:
    """The option another module added to `parser` as `old`, spelled `new` in its place in the help (its dest,
    default, type and help kept, `changes` applied), `old` read as its old spelling."""
    action = parser._option_string_actions[old]
    kept = {"dest": action.dest, "default": action.default, "type": action.type, "choices": action.choices,
            "nargs": action.nargs, "metavar": action.metavar, "help": action.help}
    kwargs = {**{k: v for k, v in kept.items() if v is not None or k == "default"}, **changes}
    group = action.container
    at = group._group_actions.index(action), parser._actions.index(action)
    group._remove_action(action)
    for spelling in action.option_strings:
        parser._option_string_actions.pop(spelling)
    added = add(group, new, old, why=why, **kwargs)
    for actions, i in zip((group._group_actions, parser._actions), at, strict=True):
        actions.remove(added)
        actions.insert(i, added)
    return added


def names(text) -> tuple[str, ...]:
    """The names of a comma-separated text, stripped, each once, in order."""
    return tuple(dict.fromkeys(t.strip() for t in str(text).split(",") if t.strip()))


def frameworks(text: str, option: str = "--frameworks") -> tuple[str, ...]:
    """The frameworks of a --frameworks text ("jax,torch"), each once; a ValueError naming `option` otherwise."""
    got = names(text)
    if not got or any(t not in FRAMEWORKS for t in got):
        raise ValueError(f"{option} {text}: expected a comma-separated subset of {', '.join(FRAMEWORKS)}")
    return got


def one_framework(command: str):
    """The check of --frameworks for a command that runs in one framework: None (not given) or one name."""
    def check(text):
        if text is None:
            return None
        got = names(text)
        if len(got) != 1 or got[0] not in FRAMEWORKS:
            raise ValueError(f"--frameworks {text}: `lagbench {command}` runs in one framework; give one of "
                             f"{', '.join(FRAMEWORKS)}")
        return got[0]
    return check


def seeds(tokens, option: str = "--seeds") -> tuple[int, ...]:
    """The seeds of an option given as comma- or space-separated integers >= 0 (`nargs="+"`), each once."""
    tokens = [tokens] if isinstance(tokens, str) else list(tokens)
    got = [t.strip() for v in tokens for t in str(v).split(",") if t.strip()]
    if not got or not all(t.isdigit() for t in got):
        raise ValueError(f"{option} {' '.join(map(str, tokens))}: expected seeds, integers >= 0, comma- or "
                         f"space-separated such as 0,1")
    return tuple(dict.fromkeys(int(t) for t in got))


SEEDS_HELP = ("the seeds themselves, comma- or space-separated, e.g. 1000,1001 (a lone number without a comma is "
              "read as --n-seeds until the next release; one seed: 1000,)")


class _SeedsOrCount(argparse.Action):
    """`run`/`tune` --seeds: the seeds, kept as given (read by `seeds_or_count`); a lone number without a
    comma is the old count, stored as --n-seeds with the notice."""

    def __call__(self, parser, namespace, values, option_string=None):
        if len(values) == 1 and values[0].strip().isdigit():
            _record(parser, namespace, "n_seeds", "--seeds N", "--n-seeds")
            notice("--seeds N (a count)", "--n-seeds N", "--seeds takes the seeds themselves, such as 1000,1001",
                   namespace)
            namespace.n_seeds = int(values[0])
            return
        setattr(namespace, self.dest, values)


def add_seeds(parser, count_help: str, seeds_help: str = SEEDS_HELP) -> None:
    """--n-seeds (a count) and --seeds (the seeds) of a command where --seeds was a count."""
    add(parser, "--n-seeds", type=int, metavar="N", help=count_help)
    parser.add_argument("--seeds", nargs="+", action=_SeedsOrCount, metavar="SEED", help=seeds_help)


def seeds_or_count(args):
    """`add_seeds`' value: None (neither given), the count (an int) or the seeds (a tuple)."""
    if args.seeds is not None and args.n_seeds is not None:
        raise ValueError(f"--seeds {' '.join(args.seeds)} and --n-seeds {args.n_seeds}: give the seeds or how "
                         f"many, not both")
    return seeds(args.seeds) if args.seeds is not None else args.n_seeds


def check(parser, dest: str, fn) -> None:
    """fn(value) -> value: run on the option `dest` of `parser`'s command by `run_checks`."""
    parser.set_defaults(**{_CHECKS: (*(parser.get_default(_CHECKS) or ()), (dest, fn))})


def run_checks(args) -> None:
    for dest, fn in getattr(args, _CHECKS, ()):
        setattr(args, dest, fn(getattr(args, dest)))


def show_defaults(parser) -> None:
    """Every option's help ends with "(default: X)" unless it writes its default itself (module doc)."""
    for action in parser._actions:
        text = action.help or ""
        if ("(default: " in text or text.startswith("required") or action.required or not action.option_strings
                or action.nargs == 0 or action.help == argparse.SUPPRESS):
            continue
        action.help = text + (" (default: none)" if action.default is None else " (default: %(default)s)")
