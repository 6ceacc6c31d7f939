"""The `lagbench` command line: `main` parses (`lagbench.cli_parser`), prepares the process and calls the
command's handler (list, run, stiff: `lagbench.cli_commands`; report and table: `lagbench.results_cli`; the
others in their packages), and ends with the exit status `lagbench.cli_exits` gives an exception."""
from __future__ import annotations

import logging
import signal
import sys
import threading

from lagbench import options
from lagbench.cli_commands import _print_errors  # noqa: F401 - imported from here by the tests
from lagbench.cli_exits import exit_status, terminate
from lagbench.cli_parser import build_parser
from lagbench.files.results import writing
from lagbench.replication.run import jax_cache

READS_ONLY = ("list", "report", "table")   # commands that compile nothing, so make no compilation cache


def main(argv=None):
    """A user's error is one line on stderr and exit 2: bad input or an OS error (a file where a folder belongs,
    no permission, a full disk); 130 for Ctrl-C and 143 for SIGTERM (with how to resume). `-v` adds the
    traceback (a user's code's own, where it failed). Any other exception is a bug in the suite: one line that
    says how to report it, exit 1, its traceback with `-v` (`lagbench.cli_exits`)."""
    for stream in (sys.stdout, sys.stderr):   # a path with undecodable bytes is printed escaped, never an error
        if hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")
    args = build_parser().parse_args(argv)
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, terminate)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(message)s")
    if args.command not in READS_ONLY:   # compiled programs shared with the processes it starts and later commands
        jax_cache.private()
    options.forget_notices()
    try:
        options.run_checks(args)   # an option's value checked before any work: one line naming it
        with writing():   # the folders the command locks are let go when it ends
            code = args.func(args)
    except (Exception, KeyboardInterrupt) as e:   # noqa: BLE001 - each kind its line and exit status
        return exit_status(e, args)
    return code or 0


if __name__ == "__main__":
    sys.exit(main())
