"""The replication, a folder per job: training/ (protocols, the one loop, JAX and PyTorch steps), evaluation/,
claims/ (records, rules, verdicts), run/ (units, runner, executors), fit/ (a user's data), tuning/ (the declared
search), studies/. The command line is `lagbench.cli`; result files are `lagbench.files.results` (layout in
docs/RESULTS.md)."""
