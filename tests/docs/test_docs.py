"""The manual's promises about itself: every page ends with a one-line-per-change version
history, names no tracker issue or work session (those belong to docs/notebook/), and every
relative link it gives leads to a file."""
import datetime
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(p for folder in (DOCS, DOCS / "tutorials", DOCS / "howto", DOCS / "reference") for p in folder.glob("*.md"))
HISTORY_LINE = re.compile(r"- (\d{4}-\d{2}-\d{2}): \S")
# Words that date a method by the work that made it rather than say what it is.
PROJECT_TALK = re.compile(r"\bissues? #?\d+|(?<![\w/])#\d{2,}\b|\bsessions?\b|\brounds? of work\b", re.IGNORECASE)
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")


def page_id(path):
    return str(path.relative_to(DOCS))


def test_the_manual_has_pages():
    assert len(PAGES) >= 25, [page_id(p) for p in PAGES]


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_each_page_ends_with_its_version_history(page):
    text = page.read_text(encoding="utf-8")
    head, sep, history = text.partition("\n## Version history\n")
    assert sep, f"{page_id(page)}: no '## Version history' section"
    lines = [line for line in history.splitlines() if line.strip()]
    assert lines, f"{page_id(page)}: the version history is empty"
    dates = []
    for line in lines:
        match = HISTORY_LINE.match(line)
        assert match, f"{page_id(page)}: '{line}' is not '- YYYY-MM-DD: what changed' (the history must be last)"
        dates.append(datetime.date.fromisoformat(match.group(1)))
    assert dates == sorted(dates, reverse=True), f"{page_id(page)}: the history is not newest first"


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_no_page_talks_of_issues_or_sessions(page):
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
        found = PROJECT_TALK.search(line)
        assert not found, f"{page_id(page)}:{number}: '{found.group(0)}' (say what it is, not when it was made)"


@pytest.mark.parametrize("page", PAGES + [ROOT / "README.md"], ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_leads_to_a_file(page):
    for target in LINK.findall(page.read_text(encoding="utf-8")):
        if re.match(r"[a-z]+:", target):
            continue  # a web address
        assert (page.parent / target).exists(), f"{page.relative_to(ROOT)}: the link '{target}' leads nowhere"
