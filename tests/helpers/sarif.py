"""Validation against the official SARIF 2.1.0 schema (tests/data/sarif, no network)."""

from __future__ import annotations

import json
from pathlib import Path

from jsonschema import Draft4Validator

SCHEMA = json.loads((Path(__file__).resolve().parents[1] / "data" / "sarif" / "sarif-schema-2.1.0.json").read_text())


def assert_valid(log: dict) -> None:
    validator = Draft4Validator(SCHEMA, format_checker=Draft4Validator.FORMAT_CHECKER)
    errors = sorted(validator.iter_errors(log), key=lambda e: list(e.path))
    assert not errors, "\n".join(f"{list(e.path)}: {e.message}" for e in errors[:5])
