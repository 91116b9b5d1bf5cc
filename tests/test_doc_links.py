"""Every relative link of the README and docs/ leads somewhere: the file exists and an #anchor
names one of its headings (GitHub's slugs), so a page cut or renamed cannot leave a reader at a
dead end. No YADE needed."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK = re.compile(r"\]\(([^)\s]+)\)")


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


def test_every_relative_link_of_the_docs_resolves():
    assert PAGES and not _dead_links()


def test_a_dead_link_is_found(tmp_path, monkeypatch):
    """The check itself: a link to a missing page and one to a missing heading are reported."""
    page = tmp_path / "page.md"
    page.write_text("# Title\n[a](missing.md) [b](#no-such) [c](#title) [d](https://x.org)\n")
    monkeypatch.setattr(__import__(__name__), "PAGES", [page])
    assert _dead_links() == ["page.md: missing.md (no such file)",
                             "page.md: #no-such (no such heading)"]
