"""Options given a new name: the old spelling is still read, with a deprecation notice, for a while."""
from __future__ import annotations

import sys


def renamed(command: str, new, old, default, new_flag: str, old_flag: str, why: str = ""):
    """The value of an option of `command`, given as `new_flag` (value `new`, `default` when not given) or as
    its earlier spelling `old_flag` (value `old`, None when not given): the old one with a notice on stderr
    (`why` says what the old name means elsewhere); a ValueError when both are given."""
    if old is None:
        return new
    if new != default:
        raise ValueError(f"{old_flag}: give it once, as {new_flag}")
    print(f"lagbench: {command} {old_flag} is deprecated; use {new_flag}{f' ({why})' if why else ''}",
          file=sys.stderr)
    return old
