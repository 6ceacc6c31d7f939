"""Score a predictor from outside the suite on a system of `systems`, as the suite scores its own models."""
