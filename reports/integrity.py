"""Checksums of result files: the canonical form the runner must write and the report verifies.

Canonical form of a ``result.json`` checksum (the writer must match it byte for byte):

    body = {k: v for k, v in result.items() if k != "checksum"}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"))   # ensure_ascii=True, allow_nan=True (defaults)
    checksum = hashlib.sha256(text.encode("utf-8")).hexdigest()      # 64 lowercase hex digits

Only the top-level ``"checksum"`` key is dropped; nested keys are sorted too (``sort_keys`` is recursive).
Every entry of ``result["files"]`` maps a path relative to the unit folder to the lowercase hex sha256
of that file's bytes. The code that computes both is the writer's own (`lagbench.files.results`: `canonical`,
`result_checksum`, `sha256_file`; NumPy only, no training code); this module adds the report's
verification, which names what is wrong instead of raising.
"""

from __future__ import annotations

from pathlib import Path

from lagbench.files.results import canonical, result_checksum
from lagbench.files.results import sha256_file as file_sha256

__all__ = ["canonical_json", "result_checksum", "file_sha256", "verify_unit"]


def canonical_json(result: dict) -> str:
    """The canonical JSON text of ``result`` without its top-level ``"checksum"`` key."""
    return canonical({k: v for k, v in result.items() if k != "checksum"}).decode("utf-8")


def verify_unit(unit_dir: Path, result: dict) -> str | None:
    """Return ``None`` when the result and every listed file match, else a short reason."""
    stored = result.get("checksum")
    if not isinstance(stored, str):
        return "no checksum"
    if result_checksum(result) != stored.lower():
        return "result.json checksum mismatch"
    files = result.get("files") or {}
    if not isinstance(files, dict):
        return "'files' is not a mapping"
    for rel, digest in sorted(files.items()):
        path = (unit_dir / rel).resolve()
        if unit_dir.resolve() not in path.parents:
            return f"listed file {rel} outside the unit folder"
        if not path.is_file():
            return f"listed file {rel} missing"
        if not isinstance(digest, str) or file_sha256(path) != digest.lower():
            return f"{rel} sha256 mismatch"
    return None
