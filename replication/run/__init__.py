"""Orchestration: units of work, the resumable runner, the executors (in-process, worker processes, Ray),
the duration estimate and the environment a result records."""
