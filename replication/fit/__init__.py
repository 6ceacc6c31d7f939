"""Bring your own data: `lagbench simulate / fit / evaluate`: data files, their rows and split, the fit
task, its evaluation, and loading a fitted model back."""
