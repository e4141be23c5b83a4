"""The README's, CHANGES.md's and the format documents' links lead somewhere: every
``(#anchor)`` names a heading of its own file (as GitHub makes anchors of headings), every
relative link an existing file (and a heading of it, with ``#anchor``), and the README's
contents list names every section, in order."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [
    ROOT / "README.md",
    ROOT / "CHANGES.md",
    *sorted((ROOT / "docs" / "formats").glob("*.md")),
]
LINK = re.compile(r"\]\(([^)\s]+)\)")
HEADING = re.compile(r"^(#{1,6}) (.+)$")


def headings(text: str) -> list[tuple[int, str]]:
    """The (level, text) of each Markdown heading outside fenced code, in order."""
    found, fenced = [], False
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced and (match := HEADING.match(line)):
            found.append((len(match.group(1)), match.group(2).strip()))
    return found


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but - and _ dropped, spaces -."""
    return re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-")


def anchors(text: str, levels: tuple[int, ...] = (1, 2, 3, 4, 5, 6)) -> list[str]:
    """The anchor of every heading of those levels; a repeated one (counting every level) gets
    -1, -2, ... as GitHub numbers them."""
    seen: dict[str, int] = {}
    made = []
    for level, heading in headings(text):
        plain = anchor(heading)
        if level in levels:
            made.append(plain if plain not in seen else f"{plain}-{seen[plain]}")
        seen[plain] = seen.get(plain, 0) + 1
    return made


def test_anchor_follows_github():
    assert anchor("The self-parking car (the 1990 paper's §6)") == (
        "the-self-parking-car-the-1990-papers-6"
    )
    assert anchor("Looking inside a result (`mosys info`)") == "looking-inside-a-result-mosys-info"
    assert anchors("# a\n## b\n```\n## b\n```\n## b\n") == ["a", "b", "b-1"]


@pytest.mark.parametrize("path", DOCUMENTS, ids=lambda path: path.name)
def test_links_lead_somewhere(path: Path):
    text = path.read_text(encoding="utf-8")
    broken = []
    for target in LINK.findall(text):
        if target.startswith(("http://", "https://", "mailto:")):
            continue
        file, _, fragment = target.partition("#")
        linked = path.parent / file if file else path
        leads = linked.exists() and (
            not fragment or fragment in anchors(linked.read_text(encoding="utf-8"))
        )
        if not leads:
            broken.append(target)
    assert not broken, f"{path.name}: links to nowhere: {broken}"


def test_the_contents_list_every_section_in_order():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    contents = text[text.index("<summary>Contents</summary>") : text.index("</details>")]
    listed = re.findall(r"^( *)- \[(.+)\]\(#([^)]+)\)$", contents, flags=re.MULTILINE)
    sections = [(level, heading) for level, heading in headings(text) if level in (2, 3)]
    assert [(len(indent) // 2 + 2, heading) for indent, heading, _ in listed] == sections
    assert [target for _, _, target in listed] == anchors(text, levels=(2, 3))
