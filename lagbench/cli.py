"""The `lagbench` command line: list, run, report, fit, bench (report and table: `results_cli.py`)."""
from __future__ import annotations

import argparse
import logging
import signal
import sys
import threading
import traceback
from pathlib import Path

from lagbench import options
from lagbench.files.results import DiskFull, writing
from lagbench.replication.run import jax_cache
from lagbench.replication.training.device import HELP as DEVICE_HELP
from lagbench.speedstudy.bench_cli import add_bench
from lagbench.speedstudy.train_target_cli import add_train_target


def _csv(s):
    return [x.strip() for x in s.split(",") if x.strip()] if s else None


def write_folder(path: Path) -> Path:
    """The output folder, made and checked before any work (a ValueError naming --out)."""
    from lagbench.files.results import output_folder

    return output_folder(path, "--out")


def cmd_list(args):
    from lagbench import systems
    from lagbench.models import ACTIVATIONS, INITS, KINDS
    from lagbench.replication.claims import CLAIMS, PROFILES, get

    if args.claim or args.profile:   # one claim as it runs under one profile (`claims.resolved`)
        from lagbench.replication.claims.resolved import resolved

        if not (args.claim and args.profile):
            raise ValueError("--claim and --profile go together: what a claim runs depends on the profile")
        if args.profile not in PROFILES:
            raise ValueError(f"--profile: unknown {args.profile!r}; valid: {', '.join(PROFILES)}")
        c = get(args.claim)
        print(f"claim {c.number} {c.id} [{c.paper} {c.section}] under profile {args.profile}: {c.title}")
        print(f"evaluation: {c.evaluate}; metric: {c.metric}")
        print("\n".join(resolved(c, args.profile).describe()))
        return 0
    print("systems:    " + ", ".join(systems.names()))
    print("models:     " + ", ".join(KINDS))
    print("activations:" + " " + ", ".join(ACTIVATIONS))
    print("inits:      " + ", ".join(INITS))
    print("profiles:   " + ", ".join(PROFILES))
    print("claims (a check tests the implementation or the numerics, not a paper claim):")
    for c in CLAIMS.values():
        print(f"  {c.number:>2} {c.id:<17} [{c.paper} {c.section}]{' (check)' if c.kind == 'check' else ''} {c.title}")
        print(f"     models: {', '.join(c.paper_models())}")
        print(f"     parts: {'; '.join(p.name + (' (check)' if p.check else '') for p in c.parts)}")
        if c.controls():
            print(f"     positive controls: {', '.join(c.controls())}")
        for var in c.variants:
            print(f"     variant: {var.name} ({', '.join(v for _, v in var.replaces)}; never decides)")


def cmd_run(args):
    from lagbench.replication.claims.base import run_frameworks
    from lagbench.replication.run.runner import run
    from lagbench.replication.training import device

    frameworks = _csv(args.frameworks)   # None: the profile's (`PROFILE_FRAMEWORKS`)
    seeds = options.seeds_or_count(args)   # None: the profile's
    device.apply(args.device, run_frameworks(args.profile, frameworks))
    summary = run(profile=args.profile, out=args.out or f"results/{args.profile}", claims=_csv(args.claims),
                  frameworks=frameworks, seeds=seeds, models=_csv(args.models),
                  progress=not args.quiet, jobs=args.jobs, executor=args.executor, address=args.address,
                  dry_run=args.dry_run, split=args.split, add_models=args.add_model, store=args.store)
    if summary.get("dry_run"):
        return 0
    from lagbench.reports.load import asked_claims

    asked = asked_claims(Path(args.out or f"results/{args.profile}"), earlier=False)   # this run's, as run.json has them
    for c in summary["claims"]:   # the claims this run was asked for (the summary holds every claim)
        if asked is None or c["id"] in asked:
            print(f"{c['id']:<17} {c['verdict']:<15} {c['reason']}")
    return _print_errors(summary.get("errors", []))


def _print_errors(errors) -> int:
    """Each unit error once, units failing with the same message on one line; the exit status: 2 where the
    user's code failed (a rerun cannot help), 1 for other errors (a rerun retries them), 0 for none."""
    from lagbench.files.user_functions import is_users

    by_message: dict = {}
    for e in errors:
        unit, _, message = e.partition(": ")
        by_message.setdefault(message, []).append(unit)
    for message, units in by_message.items():
        which = f"unit {units[0]}" if len(units) == 1 else f"{len(units)} units ({', '.join(units)})"
        tail = "" if is_users(message) else " (no result written; a rerun retries it)"
        print(f"lagbench: error in {which}: {message}{tail}", file=sys.stderr)
    return 2 if any(is_users(m) for m in by_message) else 1 if errors else 0


def cmd_stiff(args):
    from lagbench import systems
    from lagbench.replication.studies.stiff_solvers import write_study

    systems.get(args.system)  # an unknown name fails here, listing the valid ones
    folder = write_folder(Path(args.out) / "stiff")
    df = write_study(folder, args.system)
    print(df.to_string(index=False))
    print(f"picked: {df.attrs.get('reason')}; written to {folder}")


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("lagbench")
    except PackageNotFoundError:   # run from a source tree that is not installed
        return "(not installed)"


EPILOG = """usual workflows:
  lagbench run --profile quick --jobs 2 && lagbench report --results results/quick
  lagbench run --profile quick --split dev --out results/dev     development numbers (what tuning reads)
  lagbench tune --claim dp_loss                                  every model of a claim searched alike
  lagbench fit --data FILE --model lnn && lagbench report --results results/fit

option names mean one thing in every command: --frameworks (comma-separated jax, torch), --seeds (the seeds
themselves, comma- or space-separated), --n-seeds (how many), --out (what the command writes); the old
spellings (--framework, a count after --seeds, control's --results) are read until the next release, with a note.

environment variables:
  LAGBENCH_CACHE          generated code, datasets, trainings and compiled programs cache (default: .cache/)
  LAGBENCH_JAX_CACHE      0: JAX compiles every program anew (default: kept in LAGBENCH_CACHE/jax-compiled/)
  LAGBENCH_DEVICE         auto | cpu | gpu, as --device
  LAGBENCH_TORCH_COMPILE  off: PyTorch trains eagerly; on: compiles every phase it can
  LAGBENCH_TF32           1: allow TF32 matrix products on a GPU (default: full float32)
  LAGBENCH_WORKER_DIR     a Ray worker's private folder (default: /tmp/lagbench-ray-<uid>)
  LAGBENCH_BENCH_TINY     1: the speed study at its tiny preset (seconds)
  LAGBENCH_COMMIT         the commit to record where the tree has no .git"""


def build_parser():
    p = argparse.ArgumentParser(prog="lagbench", description="Replication suite for learned Lagrangian and "
                                "Hamiltonian dynamics (LNN, DeLaN, HNN, baselines) in JAX and PyTorch.",
                                epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("-v", "--verbose", action="store_true", help="log progress details; on an error, print its traceback too")
    p.add_argument("--version", action="version", version=f"lagbench {_version()}")
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("list", help="list systems, models, claims and profiles; with --claim and --profile, what "
                       "one claim runs under that profile", description="List the systems, models, activations, "
                       "initialisations, profiles and claims (each claim's paper, models, parts, positive controls "
                       "and variants); with --claim and --profile, what that claim runs under that profile.")
    s.add_argument("--claim", help="a claim id: print what it runs under --profile (its models' protocols, widths, "
                   "seeds, frameworks, evaluation config, tuned or hand-chosen) (default: none, list everything)")
    s.add_argument("--profile", help="smoke | quick | full | paper, with --claim (default: none, list everything)")
    s.set_defaults(func=cmd_list)
    s = sub.add_parser("run", help="run claims under a profile; resumes, skipping finished units",
                       description="Train and evaluate every model of the chosen claims under a profile, judge each "
                       "claim and write OUT/run.json, OUT/claims.json and OUT/units/<claim>/<framework>/<model>/"
                       "seed<k>/. A finished unit of the same protocol is kept, so the same command resumes.")
    s.add_argument("--profile", default="quick", help="smoke | quick | full | paper (default: quick)")
    s.add_argument("--claims", help="comma-separated claim ids (default: all; see `lagbench list`)")
    s.add_argument("--models", help="comma-separated model labels to restrict to (default: all; see `lagbench "
                   "list`)")
    s.add_argument("--frameworks", help="comma-separated: jax, torch (default: the profile's: jax for quick, the "
                   "preliminary profile; jax,torch for smoke, full and paper)")
    s.add_argument("--add-model", action="append", metavar="NAME=module:factory", help="your torch.nn.Module "
                   "(factory(dof)) or equinox Module (factory(dof, key)) mapping (q, qdot) to q-double-dot, trained "
                   "in every claim it fits beside the paper's models (repeatable; docs/your_model.md)")
    options.add_seeds(s, "how many seeds per claim, the split's first: dev 0.., test 1000.. (default: the "
                      "profile's; a deterministic claim keeps one)", "the seeds themselves, of --split's range, comma- or "
                      "space-separated, e.g. 1000,1001 (a lone number without a comma is read as --n-seeds until "
                      "the next release; one seed: 1000,) (default: the profile's)")
    s.add_argument("--split", default="test", choices=("test", "dev"), help="test: seeds 1000.. and held-out "
                   "data and initial conditions no protocol choice has seen, where verdicts are decided; dev: "
                   "seeds 0.. and the development draws that trials and tuning read (default: test)")
    s.add_argument("--out", help="results folder (default: results/<profile>)")
    s.add_argument("--jobs", type=int, default=1,
                   help="worker processes, one CPU thread each; units training the same model stay in one "
                        "(default: 1, everything in this process)")
    s.add_argument("--executor", default="local", choices=("local", "ray"),
                   help="local: this process or --jobs workers; ray: every unit a Ray task, on a local Ray instance "
                        "or the cluster at --address (needs `pip install 'lagbench[ray]'`) (default: local)")
    s.add_argument("--address", help="with --executor ray: the Ray cluster to join, e.g. 10.0.0.1:6379 or auto "
                   "(default: start a local Ray instance on this machine's cores)")
    s.add_argument("--dry-run", action="store_true", help="print the units and an estimated duration (a few "
                   "probed steps of each training), then stop; writes nothing")
    s.add_argument("--store", action="store_true", help="keep OUT as a store that git can carry (docs/store.md): "
                   "each finished unit trimmed to what the verdicts, the report and a resumed run read, a .gitignore "
                   "for the rest, a unit made under another registration redone, its size told at the end")
    s.add_argument("--quiet", action="store_true", help="no progress bars")
    s.add_argument("--device", default="auto", choices=("auto", "cpu", "gpu"), help=DEVICE_HELP)
    s.set_defaults(func=cmd_run)
    from lagbench.replication.run.verify_cli import add_command as add_verify
    from lagbench.replication.studies.control_cli import add_command as add_control
    from lagbench.replication.studies.online_cli import add_command as add_online
    from lagbench.replication.studies.robustness_cli import add_command as add_robustness
    from lagbench.replication.tuning.cli import add_command as add_tune
    from lagbench.results_cli import add_commands as add_results_commands

    add_tune(sub)
    add_results_commands(sub)   # report, table
    from lagbench.replication.fit.cli import add_commands

    add_commands(sub)  # simulate, fit, evaluate
    add_bench(sub)
    add_train_target(sub)
    s = sub.add_parser("stiff", help="the stiff-solver study: solvers x tolerances on a stiff system "
                                     "(writes OUT/stiff/solvers.csv for the report)",
                       description="Integrate a stiff system (stiff_chain unless --system names another) from 4 "
                       "initial states "
                       "with each solver (tsit5, dopri5, dopri8, kvaerno5 at several tolerances, and a fixed-step "
                       "Stoermer-Verlet) against a dopri8 reference at 1e-13: state and energy error, steps and "
                       "seconds per solver, and the solver picked. Writes OUT/stiff/solvers.csv and choice.json, "
                       "which `lagbench report` shows.")
    s.add_argument("--out", default="results/quick", help="results folder; writes OUT/stiff/ (default: "
                   "results/quick, which `lagbench report` reads unless given --results)")
    s.add_argument("--system", default="stiff_chain", help="a system name, see `lagbench list` (default: "
                   "stiff_chain)")
    s.set_defaults(func=cmd_stiff)
    add_control(sub)
    add_online(sub)
    add_robustness(sub)
    add_verify(sub)
    for command in sub.choices.values():   # "(default: X)" on every option that does not write its own
        options.show_defaults(command)
    return p


RESUME = {"run": "finished units are kept; run the same command again to resume",
          "bench": "run it again with --resume to keep the finished stages",
          "train-target": "the log up to the last evaluation is in {out}/train_target/train_target_log.csv",
          "fit": "no result was written; run the same command again",
          "evaluate": "no result was written; run the same command again",
          "report": "the previous report is left whole (this build was written aside and discarded); run the "
                    "same command again"}


class Terminated(KeyboardInterrupt):
    """SIGTERM (a scheduler's or `kill`'s stop), handled as Ctrl-C is: recorded, with how to resume."""


def _terminate(signum, frame):
    raise Terminated()


READS_ONLY = ("list", "report", "table")   # commands that compile nothing, so make no compilation cache


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


def main(argv=None):
    """A user's error is one line on stderr and exit 2: bad input or an OS error (a file where a folder belongs,
    no permission, a full disk); 130 for Ctrl-C and 143 for SIGTERM (with how to resume). `-v` adds the
    traceback (a user's code's own, where it failed). Any other exception is a bug in the suite: one line that
    says how to report it, exit 1, its traceback with `-v`."""
    for stream in (sys.stdout, sys.stderr):   # a path with undecodable bytes is printed escaped, never an error
        if hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")
    args = build_parser().parse_args(argv)
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminate)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(message)s")
    if args.command not in READS_ONLY:   # compiled programs shared with the processes it starts and later commands
        jax_cache.private()
    options.forget_notices()
    try:
        options.run_checks(args)   # an option's value checked before any work: one line naming it
        with writing():   # the folders the command locks are let go when it ends
            code = args.func(args)
    except (KeyError, ValueError, FileNotFoundError) as e:
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
    except DiskFull as e:
        hint = RESUME.get(args.command, "run the same command again").format(out=getattr(args, "out", None) or "OUT")
        print(f"lagbench: error: no space left on the device of {e.filename}; free space there, then: {hint}",
              file=sys.stderr)
        return 2
    except OSError as e:
        where = f": {e.filename}" if e.filename else ""
        print(f"lagbench: error: {e.strerror or e}{where}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as e:
        hint = RESUME.get(args.command, "nothing half-written was left; run the same command again")
        hint = hint.format(out=getattr(args, "out", None) or "OUT")
        how = "terminated (SIGTERM)" if isinstance(e, Terminated) else "interrupted"
        print(f"\nlagbench: {how}; {hint}", file=sys.stderr)
        return 143 if isinstance(e, Terminated) else 130
    except Exception as e:   # noqa: BLE001 - anything else is the suite's bug, reported as such
        return _bug(e, args.verbose)
    return code or 0


if __name__ == "__main__":
    sys.exit(main())
