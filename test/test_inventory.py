"""docs/inventory.md, the inventory of the reference pages (MPI 000, 001, 002): every entry is
backed by what it claims. An implemented entry names a test that exists (file and function); a
decided entry links to a heading that exists; no name appears twice."""

from __future__ import annotations

import ast
import re
from collections import Counter
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
INVENTORY = ROOT / "docs" / "inventory.md"
STATUSES = ("implemented", "decided")  # nothing is left missing
KINDS = ("function", "struct", "field", "message", "type or value", "status bit")
ROW = re.compile(r"^\| (?P<kind>[^|]+) \| `(?P<name>[^`]+)` \| (?P<page>00[012]) \| (?P<status>[^|]+) \| "
                 r"(?P<evidence>[^|]+) \|$")
LINK = re.compile(r"^\[[^\]]+\]\((?P<file>[^)#]+)#(?P<anchor>[^)]+)\)$")


def _rows() -> list[dict[str, str]]:
    lines = INVENTORY.read_text(encoding="utf-8").split("## The table", 1)[1].splitlines()
    table = [line for line in lines if line.startswith("| ") and not line.startswith(("| kind", "| ---"))]
    rows = []
    for line in table:
        match = ROW.match(line)
        assert match is not None, f"not a row of the inventory: {line}"
        rows.append({k: v.strip() for k, v in match.groupdict().items()})
    return rows


ROWS = _rows()


def _anchor(heading: str) -> str:
    """The anchor a Markdown heading gets: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


@cache
def _anchors(doc: Path) -> set[str]:
    return {_anchor(line.lstrip("#")) for line in doc.read_text(encoding="utf-8").splitlines()
            if line.startswith("#")}


@cache
def _test_names(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return {node.name for node in ast.walk(tree) if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)}


def test_the_table_is_read_whole():
    # the three pages define hundreds of names; a table that lost its rows must not pass quietly
    assert len(ROWS) > 400
    assert {row["page"] for row in ROWS} == {"000", "001", "002"}


def test_no_name_appears_twice():
    twice = [name for name, count in Counter(row["name"] for row in ROWS).items() if count > 1]
    assert twice == []


def test_every_row_has_a_kind_and_a_status():
    assert {row["kind"] for row in ROWS} <= set(KINDS)
    assert {row["status"] for row in ROWS} <= set(STATUSES)


@pytest.mark.parametrize("row", [r for r in ROWS if r["status"] == "implemented"], ids=lambda r: r["name"])
def test_an_implemented_entry_names_a_test_that_exists(row):
    evidence = row["evidence"].strip("`")
    path, _, name = evidence.partition("::")
    assert name.startswith("test_"), evidence
    file = ROOT / path
    assert file.is_file(), f"{row['name']}: no file {path}"
    assert name in _test_names(file), f"{row['name']}: no test {name} in {path}"


@pytest.mark.parametrize("row", [r for r in ROWS if r["status"] == "decided"], ids=lambda r: r["name"])
def test_a_decided_entry_links_to_a_heading_that_exists(row):
    link = LINK.match(row["evidence"])
    assert link is not None, f"{row['name']}: not a link: {row['evidence']}"
    doc = (INVENTORY.parent / link["file"]).resolve()
    assert doc.is_file(), f"{row['name']}: no document {link['file']}"
    assert link["anchor"] in _anchors(doc), f"{row['name']}: no heading #{link['anchor']} in {link['file']}"


def test_the_anchor_rule_matches_the_headings_it_is_used_on():
    # the rule test_a_decided_entry_links_to_a_heading_that_exists relies on
    assert _anchor(" The library's internals") == "the-librarys-internals"
    assert _anchor("One MotionParams: lists for counts") == "one-motionparams-lists-for-counts"
