"""The time a result file or a folder lock records: UTC, to the second, ISO 8601 (`2026-01-31T12:00:00Z`)."""
import datetime as _dt


def now() -> str:
    return _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
