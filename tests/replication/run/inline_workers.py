"""A stand-in for the executor's worker processes (`replication.run.executor._Workers`): each chain handed out is
answered at once, every unit done without failure, so a test sees the driver's side of a parallel run alone.
`on_idle()` runs each time the driver asks for a free worker (what a test wants to observe then)."""
import queue


def inline_workers(on_idle=lambda: None):
    class InlineWorkers:
        def __init__(self, jobs):
            self.results = queue.Queue()

        def idle(self):
            on_idle()
            return object()

        def assign(self, slot, cid, refs, out, members=None):
            self.results.put((cid, [(f"u{i}", None, None) for i, _ in enumerate(refs)], None, None))

        def finished(self, cid):
            pass

        def dead(self):
            return []

        def close(self, wait):
            pass

    return InlineWorkers
