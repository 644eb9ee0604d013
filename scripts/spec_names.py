"""List the names the reference pages define, for docs/inventory.md.

Usage: python -P scripts/spec_names.py SPEC_DIR > names.tsv

Prints one line per name: kind, name, page. The kinds: function (mpi*/mei* calls and
macros), struct, field (a struct's member, as Struct.member), message (MPI*Message* /
MEI*Message*), enum (any other MPI*/MEI* value or type), status (the bits of the axis
status tables: the first column of the "Motion Status" tables). The repository does not
read the reference at test time: the list lives in docs/inventory.md, and this script is
how it was made (run it again on a new edition of the pages and compare).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

IDENT = re.compile(r"\b(?:MPI|MEI|mpi|mei)[A-Za-z0-9_]+")
TYPEDEF = re.compile(r"typedef\s+(struct|enum|union)\s*\w*\s*\{")
HEADING = re.compile(r"^((?:MPI|MEI)\w+)\s*$", re.M)
STATUS_ROW = re.compile(r"^([A-Z][A-Z_]+)\t")


def kind_of(name: str) -> str:
    if name[:3] in ("mpi", "mei"):
        return "function"
    if "Message" in name and not name.endswith("Message"):
        return "message"
    return "enum"


def members(body: str, struct: str) -> list[str]:
    """Struct.member for each member line (a nested struct's members as Struct.nested.member)."""
    out: list[str] = []
    inner: list[str] | None = None  # the members of a nested struct, until its name closes it
    for line in body.splitlines():
        line = line.split("/*")[0].strip()
        closing = re.match(r"^\}\s*(\w+)\s*;", line)
        if closing and inner is not None:
            out += [f"{struct}.{closing.group(1)}.{m}" for m in inner]
            inner = None
        elif line.startswith("struct") and line.endswith("{"):
            inner = []
        else:
            found = re.match(r"^[\w\s*]+?[\s*]\**(\w+)\s*(?:\[[^\]]*\])?\s*;$", line)
            if found:
                (out if inner is None else inner).append(found.group(1) if inner is not None
                                                         else f"{struct}.{found.group(1)}")
    return out


def typedefs(text: str):
    """(kind, name, body) of each typedef block, braces matched (000 defines MPIMotionCam under
    the name MPIMotionDecelTime, a slip of the page): a block named after another section
    takes its own section's heading."""
    sections = set(HEADING.findall(text))
    for match in TYPEDEF.finditer(text):
        depth, end = 1, match.end()
        while depth:
            depth += {"{": 1, "}": -1}.get(text[end], 0)
            end += 1
        name = re.match(r"\s*(\w+)", text[end:])
        if name is None:
            continue
        title = name.group(1)
        headings = HEADING.findall(text[:match.start()])
        if headings and headings[-1] != title and title in sections and headings[-1] not in title:
            title = headings[-1]  # another section's name: the heading says which struct this is
        yield match.group(1), title, text[match.end():end - 1]


def names(page: Path) -> list[tuple[str, str]]:
    text = page.read_text(encoding="utf-8")
    found: dict[str, str] = {}
    for kind, name, body in typedefs(text):
        if kind == "enum" and not re.search(r"^\s*\w+\s+\**\w+\s*;", body, re.M):
            continue  # a real enum: its values are found as identifiers below
        found[name] = "struct"
        for member in members(body, name):
            found.setdefault(member, "field")
    for name in IDENT.findall(text):
        found.setdefault(name, kind_of(name))
    for line in text.splitlines():
        row = STATUS_ROW.match(line)
        if row and ("POSITION" in row.group(1) or row.group(1) in ("AT_TARGET", "DONE")):
            found.setdefault(row.group(1), "status")
    return sorted(found.items(), key=lambda item: (item[1], item[0]))


def main(spec_dir: str) -> None:
    seen: set[str] = set()
    for page in sorted(Path(spec_dir).glob("0*.txt")):
        for name, kind in names(page):
            if name not in seen:
                seen.add(name)
                print(f"{kind}\t{name}\t{page.name[:3]}")


if __name__ == "__main__":
    main(sys.argv[1])
