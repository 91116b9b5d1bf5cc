"""Every relative link of the README and docs/ leads somewhere: the file exists and an #anchor
names one of its headings (GitHub's slugs), so a page cut or renamed cannot leave a reader at a
dead end. And the user docs stay short and readable by users: docs/*.md hold at most LIMIT lines
in all (each measured figure lives in one page, the others link to it), and no page cites an
issue number (a user cannot read the tracker) or the shared folder outside the repository. No
YADE needed."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOCS = sorted((ROOT / "docs").glob("*.md"))
PAGES = [ROOT / "README.md", *DOCS]
LINK = re.compile(r"\]\(([^)\s]+)\)")
LIMIT = 3200
ISSUE = re.compile(r"\bissues? #?\d+", re.I)


def slug(heading):
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _dead_links():
    dead = []
    for page in PAGES:
        for target in LINK.findall(page.read_text()):
            if re.match(r"[a-z]+:", target):            # http:, https:, mailto:
                continue
            path, _, anchor = target.partition("#")
            file = (page.parent / path) if path else page
            if not file.exists():
                dead.append(f"{page.name}: {target} (no such file)")
            elif anchor and file.suffix == ".md":
                headings = re.findall(r"^#+ (.*)$", file.read_text(), re.M)
                if anchor not in {slug(h) for h in headings}:
                    dead.append(f"{page.name}: {target} (no such heading)")
    return dead


def _problems():
    """Too many lines in docs/, and each line of a page that cites an issue or ../shared."""
    problems = []
    lines = sum(len(page.read_text().splitlines()) for page in DOCS)
    if lines > LIMIT:
        problems.append(f"docs/*.md: {lines} lines, more than {LIMIT}")
    for page in PAGES:
        for number, line in enumerate(page.read_text().splitlines(), 1):
            if ISSUE.search(line):
                problems.append(f"{page.name}:{number}: cites an issue: {line.strip()}")
            if "../shared" in line:
                problems.append(f"{page.name}:{number}: names ../shared: {line.strip()}")
    return problems


def test_every_relative_link_of_the_docs_resolves():
    assert PAGES and not _dead_links()


def test_docs_are_short_and_cite_no_issue():
    assert DOCS and not _problems()


def test_the_checks_find_what_they_look_for(tmp_path, monkeypatch):
    """The checks themselves: a link to a missing page and one to a missing heading; too many
    lines, an issue number and ../shared."""
    page = tmp_path / "page.md"
    page.write_text("# Title\n[a](missing.md) [b](#no-such) [c](#title) [d](https://x.org)\n"
                    "fixed in Issue 45.\nsee ../shared/notes\n")
    module = __import__(__name__)
    monkeypatch.setattr(module, "DOCS", [page])
    monkeypatch.setattr(module, "PAGES", [page])
    monkeypatch.setattr(module, "LIMIT", 3)
    assert _dead_links() == ["page.md: missing.md (no such file)",
                             "page.md: #no-such (no such heading)"]
    assert _problems() == ["docs/*.md: 4 lines, more than 3",
                           "page.md:3: cites an issue: fixed in Issue 45.",
                           "page.md:4: names ../shared: see ../shared/notes"]
