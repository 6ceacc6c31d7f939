"""The handlers of `lagbench list`, `run` and `stiff` (registered by `lagbench.cli_parser`): each takes the parsed
arguments and returns the exit status (None for 0); bad input raises a ValueError naming the option, which
`lagbench.cli.main` prints as one line. `_print_errors` prints a run's unit errors and picks its exit status."""
from __future__ import annotations

import sys
from pathlib import Path

from lagbench import options


def _csv(s):
    """The names of a comma-separated option as a list, duplicates kept (the runner refuses a name given
    twice); None where the option is not given."""
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
    from lagbench.replication.run import environment
    from lagbench.replication.run.runner import run
    from lagbench.replication.training import device

    frameworks = _csv(args.frameworks)   # None: the profile's (`PROFILE_FRAMEWORKS`)
    seeds = options.seeds_or_count(args)   # None: the profile's
    if environment.worker_torch_threads(args.executor, args.jobs) is not None:
        environment.one_thread_jax()   # the estimate's JAX probes at the workers' one thread, before the
        # device check below starts JAX's backend
    device.apply(args.device, run_frameworks(args.profile, frameworks))
    summary = run(profile=args.profile, out=args.out or f"results/{args.profile}", claims=_csv(args.claims),
                  frameworks=frameworks, seeds=seeds, models=_csv(args.models),
                  progress=not args.quiet, jobs=args.jobs, executor=args.executor, address=args.address,
                  dry_run=args.dry_run, split=args.split, add_models=args.add_model, store=args.store,
                  pack_seeds=args.pack_seeds)
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
