"""Evaluation: NumPy views of trained models (adapters), the fixed-step integrator, the metrics, and the
evaluation routines that claims name (registry)."""
