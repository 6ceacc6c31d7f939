"""Side studies that are not claims: the velocity-Hessian study and the stiff-solver study."""
