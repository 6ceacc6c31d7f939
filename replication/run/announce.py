"""What a long run prints before it starts: its units by claim and its estimated duration
(`replication.run.estimate`), with where the time goes by claim, model and framework, and, where seeds are
packed (`--pack-seeds`, or a GPU), the packed run's duration beside the plain one."""
from __future__ import annotations

from lagbench.replication.run import environment as env
from lagbench.replication.run.estimate import PROBES, describe, estimate
from lagbench.replication.training import device as dev


def announce(profile, units, todo, out, jobs, executor="local", keep=False, members=None) -> dict:
    """Print the units a long profile will run and its estimated duration (`replication.run.estimate`),
    its probes timed at the thread setting the units will train with; `keep`: the probes are written to
    OUT for a resumed run on this machine to reuse. `members`: the run's packing (`packing.members`)."""
    print(f"lagbench: profile {profile}: {len(units)} units, {len(todo)} to run:\n{describe(units, todo)}", flush=True)
    print("lagbench: timing a few steps of each training to estimate the duration...", flush=True)
    est = estimate(todo, out, jobs, env.worker_torch_threads(executor, jobs), keep=keep, members=members)
    if est["probes_reused"]:
        print(f"lagbench: {est['probes_reused']} of {est['probes']} probes read from an earlier invocation on this "
              f"machine (OUT/{PROBES}; remove it to probe again)", flush=True)
    hw = env.hardware()
    where = ", ".join(f"{fw} on the {dev.resolve(dev.request(), fw).upper()}" for fw in sorted({u.framework for u in todo}))
    print(f"lagbench: {est['trainings']} trainings to do ({est['cached']} reused from OUT/trained), estimated "
          f"{est['train_s'] / 3600:.1f} h of training, about {est['wall_s'] / 3600:.1f} h wall with {jobs} "
          f"worker{'s' if jobs != 1 else ''} (evaluation not included; {where}; {hw['cpu']}, GPU: {hw['gpu']}). "
          f"Interrupt at any time: the run resumes where it stopped.", flush=True)
    if est.get("cohorts"):   # each model's seeds packed as one program (`replication.run.packing`)
        c, most = est["cohorts"], max((members or {}).values(), default=1)
        this = "as this run packs them" if most > 1 else "this run trains one seed a program"
        on_gpu = " on the GPU" if most < 2 else ""
        print(f"lagbench: with each model's seeds packed as one program{on_gpu} ({c['programs']} programs of up "
              f"to {c['members']} seeds; {this}): {c['train_s'] / 3600:.1f} h of "
              f"training, about {c['wall_s'] / 3600:.1f} h wall with {jobs} worker{'s' if jobs != 1 else ''}",
              flush=True)
    if len(est["by_claim"]) > 1:   # where the time goes, the costliest first (shared trainings: first claim)
        print("lagbench: training by claim: " + ", ".join(f"{c} {s / 3600:.2f} h" for c, s in est["by_claim"].items()
                                                        if s > 0), flush=True)
    if len(est.get("by_model", {})) > 1:   # and within each claim, by model and framework
        for claim in (c for c, s in est["by_claim"].items() if s > 0):
            parts = [f"{m} {fw} {s / 3600:.2f} h" for (c, m, fw), s in est["by_model"].items() if c == claim and s > 0]
            print(f"lagbench:   {claim}: {', '.join(parts)}", flush=True)
    return est
