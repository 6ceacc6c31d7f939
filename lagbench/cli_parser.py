"""The `lagbench` argument parser: `build_parser()` registers every command, its options and its handler
(`func`): list, run and stiff here (handlers in `lagbench.cli_commands`), the others by their own modules'
`add_command(s)`. Every option's help ends with its default (`options.show_defaults`)."""
from __future__ import annotations

import argparse

from lagbench import options
from lagbench.cli_commands import cmd_list, cmd_run, cmd_stiff
from lagbench.replication.training.device import HELP as DEVICE_HELP
from lagbench.speedstudy.bench_cli import add_bench
from lagbench.speedstudy.train_target_cli import add_train_target


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
    s.add_argument("--pack-seeds", type=int, metavar="N", help="train up to N seeds of a model side by side as one "
                   "vectorised program, each with its own init and batches and stored under the training key of its "
                   "run alone (docs/gpu.md); it changes float32 rounding, not the protocol, so registrations are "
                   "made with it off; a protocol with restarts, an early stop or a cohort of its own trains as it "
                   "registers; local executor only (default: 8 where a framework trains on a GPU, 1 = each seed "
                   "alone on the CPU)")
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
