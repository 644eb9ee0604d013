"""Every citation of a section of the repository's own documents names a section that exists.

Code, tests and docs cite the docs and bench/RESULTS.md by document and section, e.g.
``(docs/reliability.md, "The goal path")``: a comma, then the section's title or its start.
A section is a heading or a bold lead (``- **Blending** ...``). When a section is renamed or
its figures leave bench/RESULTS.md (they stay in git), the citation must follow. A colon
instead of the comma (``docs/paths.md: "3rd order"``) quotes the document's words and is not
checked here.
"""

from __future__ import annotations

import re
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CITATION = re.compile(r'((?:docs/[\w./-]+|bench/RESULTS)\.md),\s+(?:sections?\s+)?"([^"]+)"')
# A line break inside a citation, with what continues a comment or a docstring's list item.
_BREAK = re.compile(r"\s*\n\s*(?:#+\s*|\*\s*)?")


@cache
def sections(document: Path) -> tuple[str, ...]:
    text = document.read_text(encoding="utf-8")
    headings = [line.lstrip("#").strip() for line in text.splitlines() if line.startswith("#")]
    return (*headings, *re.findall(r"\*\*([^*]+)\*\*", text))


def citations() -> list[tuple[str, str, str]]:
    files = [*ROOT.glob("mpi_ros/**/*.py"), *ROOT.glob("test/**/*.py"), *ROOT.glob("bench/*.py"),
             *ROOT.glob("docs/**/*.md"), *ROOT.glob("examples/**/*.py"), ROOT / "README.md"]
    found = []
    for path in sorted(files):
        text = _BREAK.sub(" ", path.read_text(encoding="utf-8"))
        found += [(str(path.relative_to(ROOT)), document, title) for document, title in CITATION.findall(text)]
    return found


def test_the_repository_cites_its_documents():
    # The pattern still finds the citations (a rewrite of their form would empty the check).
    assert len(citations()) > 100


@pytest.mark.parametrize(("where", "document", "title"), citations())
def test_a_cited_section_exists(where, document, title):
    path = ROOT / document
    assert path.is_file(), f"{where} cites {document}, which does not exist"
    assert any(section.startswith(title) for section in sections(path)), (
        f'{where} cites {document}, "{title}": no heading or bold lead of it starts so')
