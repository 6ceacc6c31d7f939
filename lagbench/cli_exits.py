"""How a `lagbench` command ends on an exception: `exit_status(e, args)` prints what the user needs and returns
the exit status. A user's error is one line on stderr and exit 2: bad input (KeyError, ValueError,
FileNotFoundError) or an OS error (a file where a folder belongs, no permission, a full disk); 130 for Ctrl-C
and 143 for SIGTERM (`Terminated`, raised by `terminate`), with how to resume (`RESUME`). `-v` adds the
traceback (a user's code's own, where it failed). Any other exception is a bug in the suite: one line that
says how to report it, exit 1, its traceback with `-v`. It is called while the exception is handled, so that
the traceback printed is that exception's."""
from __future__ import annotations

import sys
import traceback

from lagbench.files.results import DiskFull

RESUME = {"run": "finished units are kept; run the same command again to resume",
          "bench": "run it again with --resume to keep the finished stages",
          "train-target": "the log up to the last evaluation is in {out}/train_target/train_target_log.csv",
          "fit": "no result was written; run the same command again",
          "evaluate": "no result was written; run the same command again",
          "report": "the previous report is left whole (this build was written aside and discarded); run the "
                    "same command again"}


class Terminated(KeyboardInterrupt):
    """SIGTERM (a scheduler's or `kill`'s stop), handled as Ctrl-C is: recorded, with how to resume."""


def terminate(signum, frame):
    """The SIGTERM handler."""
    raise Terminated()


REPORT = ("a bug in lagbench, not in your input: please report it with the command you ran, the traceback "
          "that `lagbench -v ...` prints and `pip show lagbench`'s version")


def _internal(e: BaseException) -> bool:
    """A KeyError whose message is not a sentence (a lookup that failed inside the suite, `KeyError('lr')`):
    the suite's own errors for bad input say what is wrong in words."""
    return isinstance(e, KeyError) and not (e.args and isinstance(e.args[0], str) and " " in e.args[0])


def _bug(e: BaseException, verbose: bool) -> int:
    if verbose:
        traceback.print_exc()
    print(f"lagbench: internal error: {type(e).__name__}: {e}; {REPORT}"
          + ("" if verbose else " (rerun with -v for the traceback)"), file=sys.stderr)
    return 1


def exit_status(e: BaseException, args) -> int:
    """The exit status of the command `args` ended by `e` (an Exception or a KeyboardInterrupt), its line
    printed on stderr."""
    if isinstance(e, KeyError | ValueError | FileNotFoundError):
        if _internal(e):
            return _bug(e, args.verbose)
        msg = e.args[0] if isinstance(e, KeyError) and e.args else e
        if args.verbose:   # a user's code failed: its traceback, not the suite's
            details = getattr(e, "details", "")
            if details:
                print(details, file=sys.stderr, end="" if details.endswith("\n") else "\n")
            else:
                traceback.print_exc()
        print(f"lagbench: error: {msg}", file=sys.stderr)
        return 2
    if isinstance(e, DiskFull):
        hint = RESUME.get(args.command, "run the same command again").format(out=getattr(args, "out", None) or "OUT")
        print(f"lagbench: error: no space left on the device of {e.filename}; free space there, then: {hint}",
              file=sys.stderr)
        return 2
    if isinstance(e, OSError):
        where = f": {e.filename}" if e.filename else ""
        print(f"lagbench: error: {e.strerror or e}{where}", file=sys.stderr)
        return 2
    if isinstance(e, KeyboardInterrupt):
        hint = RESUME.get(args.command, "nothing half-written was left; run the same command again")
        hint = hint.format(out=getattr(args, "out", None) or "OUT")
        how = "terminated (SIGTERM)" if isinstance(e, Terminated) else "interrupted"
        print(f"\nlagbench: {how}; {hint}", file=sys.stderr)
        return 143 if isinstance(e, Terminated) else 130
    return _bug(e, args.verbose)   # anything else is the suite's bug, reported as such
