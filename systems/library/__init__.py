"""System families, one per file; each module exposes builders ``build_<name>(**options) -> Definition``."""
