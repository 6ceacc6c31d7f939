"""`renamed`, the old spellings' notice for an option a command resolves itself: written once in
`lagbench.options` (with every command's old spellings), named here for `replication.fit.options`."""
from lagbench.options import renamed

__all__ = ["renamed"]
