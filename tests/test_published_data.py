"""tests/data/published.toml, the published numbers the verification tests read: every table names its
source, as tests/data/README.md says."""
from __future__ import annotations

import tomllib
from pathlib import Path

TESTS = Path(__file__).resolve().parent
DATA = TESTS / "data" / "published.toml"


def test_every_published_table_names_its_source():
    doc = tomllib.loads(DATA.read_text())
    assert doc, "published.toml is empty"
    missing = [name for name, table in doc.items()
               if not (isinstance(table, dict) and isinstance(table.get("source"), str) and len(table["source"]) > 20)]
    assert not missing, f"tables of published.toml without a source: {missing}"

