"""The documentation site builds with MkDocs in strict mode (a broken link or anchor is an error), every page
of docs/ is in its navigation, and the README's links point at files that exist."""

from __future__ import annotations

import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest
import yaml
from conftest import ROOT

pytest.importorskip("mkdocs")


class _Links(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.hrefs: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if name in ("href", "src") and value:
                self.hrefs.append(value)


def test_site_builds_strict_and_every_local_link_resolves(tmp_path: Path) -> None:
    site = tmp_path / "site"
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT, capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    pages = sorted(site.rglob("*.html"))
    assert len(pages) >= 20  # every page of the manual, and MkDocs' own 404 and search pages
    broken, checked = [], 0
    for page in pages:
        if page.name == "404.html":
            continue  # MkDocs writes it with links from the site's root, for any depth it is served at
        parser = _Links()
        parser.feed(page.read_text(encoding="utf-8"))
        for href in parser.hrefs:
            target = href.split("#", 1)[0].split("?", 1)[0]
            if not target or re.match(r"^[a-z]+:|^//", target):
                continue  # an anchor on the page itself, or an address outside the site
            checked += 1
            resolved = (page.parent / target).resolve()
            if not (resolved.exists() or (resolved / "index.html").exists()):
                broken.append(f"{page.relative_to(site)}: {href}")
    assert broken == [] and checked > 200  # the navigation alone links every page from every page


def _nav_pages(items: list[object]) -> list[str]:
    out: list[str] = []
    for item in items:
        value = next(iter(item.values())) if isinstance(item, dict) else item
        out.extend(_nav_pages(value) if isinstance(value, list) else [str(value)])
    return out


def test_every_page_is_in_the_navigation() -> None:
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    pages = sorted(p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md"))
    assert sorted(_nav_pages(config["nav"])) == pages


def test_readme_links_point_at_files() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    assert links and all((ROOT / link).exists() for link in links if not re.match(r"^[a-z]+:", link))
