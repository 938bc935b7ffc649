"""Check a built site as a reader opening it from files would use it: every local link and
asset of every page resolves to a file (a link to a folder would show a file listing or
nothing from ``file://``), and every page is reached from the home page's navigation.

Usage: ``python docs/hooks/check_site.py site`` (run by ``make docs`` after the build);
prints one line per broken link and exits 1 if there is any.
"""

from __future__ import annotations

import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links: list[str] = []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name in ("href", "src") and value:
                self.links.append(value)


def local_targets(page: Path) -> list[tuple[str, Path]]:
    """(link as written, the file it points to) of every local link on ``page``."""
    parser = _Links()
    parser.feed(page.read_text(encoding="utf-8"))
    out = []
    for link in parser.links:
        parts = urlsplit(link)
        if parts.scheme or parts.netloc or not parts.path:
            continue  # another site, a data: URI, or an anchor on this page
        out.append((link, (page.parent / unquote(parts.path)).resolve()))
    return out


def check(site: Path) -> list[str]:
    site = site.resolve()
    pages = sorted(p for p in site.rglob("*.html") if p.name != "404.html")
    problems = []
    for page in pages:
        for link, target in local_targets(page):
            if not target.is_file():
                kind = "a folder" if target.is_dir() else "missing"
                problems.append(f"{page.relative_to(site)}: {link} -> {kind}")
    reached, todo = {site / "index.html"}, [site / "index.html"]
    while todo:
        for _, target in local_targets(todo.pop()):
            if target.suffix == ".html" and target.is_file() and target not in reached:
                reached.add(target)
                todo.append(target)
    problems += [
        f"{p.relative_to(site)}: not reached from index.html" for p in pages if p not in reached
    ]
    return problems


if __name__ == "__main__":
    found = check(Path(sys.argv[1] if len(sys.argv) > 1 else "site"))
    for line in found:
        print(line)
    print(f"site check: {len(found)} problem(s)")
    sys.exit(1 if found else 0)
