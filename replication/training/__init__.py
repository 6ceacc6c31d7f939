"""Training: the protocol, its data and schedules, the objective, the one loop (written once) with its
JAX and PyTorch optimiser steps, restarts (scouting), held-out tracking, and the training cache."""
