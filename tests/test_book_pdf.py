"""The printed book (``make pdf``): one PDF that opens, with every chapter, text on its pages,
the sources' Chinese terms in a CJK font, and maths typeset.

Run after ``make pdf`` (``make test`` runs it after the strict build and the browser check): the
PDF is ``book/_build/pdf/book.pdf``, printed by scripts/book_pdf.py from the single-page build.
Only a sample of pages is read (the first, the opening pages of the time-series chapter, the
register), so the check takes seconds.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PDF = ROOT / "book" / "_build" / "pdf" / "book.pdf"
SINGLE = ROOT / "book" / "_build" / "singlehtml"

pytestmark = pytest.mark.browser

RAW_TEX = re.compile(r"\$\$|\\\(|\\\)|\\(frac|mathrm|mathbf|left|right|begin|sqrt)\b")
"""Maths the printer left as TeX source."""


def _chapters() -> list[str]:
    """Chapter and page titles of the book, in order, from the single-page build's contents."""
    import html as html_lib

    entry = max((p for p in SINGLE.glob("*.html") if p.name not in {"genindex.html", "search.html"}),
                key=lambda p: p.stat().st_size)
    text = entry.read_text(encoding="utf-8")
    found = re.findall(r'<li class="toctree-l1[^"]*"><a class="reference internal[^"]*" href="#document-[^"]*">(.*?)</a>', text)
    titles = [html_lib.unescape(re.sub(r"<[^>]+>", "", t)).strip() for t in found]
    return list(dict.fromkeys(titles))     # the contents and the navigation list the same chapters


@pytest.fixture(scope="module")
def reader():
    if not PDF.exists():
        pytest.fail(f"{PDF.relative_to(ROOT)} is missing: run `make pdf` (part of `make test`) first")
    if SINGLE.exists() and PDF.stat().st_mtime < max(p.stat().st_mtime for p in SINGLE.glob("*.html")):
        pytest.fail("the PDF is older than the single-page build it prints: run `make pdf`")
    from pypdf import PdfReader

    return PdfReader(PDF)


@pytest.fixture(scope="module")
def outline(reader) -> list[tuple[str, int]]:
    """(title, page index) of every bookmark, depth first."""
    out = []

    def walk(items):
        for x in items:
            if isinstance(x, list):
                walk(x)
            else:
                out.append((" ".join(x.title.split()), reader.get_destination_page_number(x)))

    walk(reader.outline)
    return out


def _squash(s: str) -> str:
    return re.sub(r"\s+", "", s)


def _page(outline, title: str) -> int:
    hits = [p for t, p in outline if _squash(title) in _squash(t)]
    assert hits, f"no bookmark for {title!r} in the PDF"
    return hits[0]


def test_the_pdf_opens_and_holds_every_chapter(reader, outline):
    n = len(reader.pages)
    chapters = _chapters()
    assert len(chapters) >= 20, f"the single-page build lists only {len(chapters)} chapters"
    # every chapter opens a new page (print.css): at least a page per chapter, and the book's
    # text, tables and figures fill far more
    assert n > 10 * len(chapters), f"{n} pages for {len(chapters)} chapters"
    pages = [_page(outline, c) for c in chapters]
    assert pages == sorted(pages) and len(set(pages)) == len(pages), \
        f"chapters do not start on distinct pages in order: {list(zip(chapters, pages))}"
    assert pages[-1] < n


def test_sampled_pages_have_text_and_typeset_maths(reader, outline):
    """The first page, the opening page of a chapter in the middle of the book, the register:
    each carries text, none shows TeX source."""
    samples = {"first page": (0, "Reproducing SINS/GNSS research"),
               "time-series chapter": (_page(outline, "Gravity-disturbance time series"), "stationarity"),
               "register": (_page(outline, "Register of errata and inconsistencies"), "printed")}
    for label, (i, expected) in samples.items():
        text = reader.pages[i].extract_text() or ""
        assert len(text.split()) >= 40, f"{label} (page {i + 1}) is nearly blank: {text[:200]!r}"
        assert expected.lower() in text.lower(), f"{label} (page {i + 1}) lacks {expected!r}: {text[:300]!r}"
        assert not RAW_TEX.search(text), f"{label} (page {i + 1}) shows TeX source: {RAW_TEX.search(text).group(0)}"
    assert 0 < samples["time-series chapter"][0] < len(reader.pages) - 1


def _fonts(page) -> set[str]:
    res = page.get("/Resources") or {}
    fonts = res.get_object().get("/Font") or {}
    return {str(f.get_object().get("/BaseFont", "")) for f in fonts.get_object().values()}


def test_chinese_terms_are_printed_in_a_cjk_font(reader, outline):
    """The time-series chapter quotes 逆序检验 near its start: the text is there and a CJK font
    (WenQuanYi Zen Hei, or another with CJK in its name) is embedded to draw it."""
    start = _page(outline, "Gravity-disturbance time series")
    for i in range(start, min(start + 4, len(reader.pages))):
        if "逆序检验" in (reader.pages[i].extract_text() or ""):
            fonts = _fonts(reader.pages[i])
            assert any(re.search(r"WenQuanYi|CJK|Hei|Song|Ming|Noto Sans SC", f, re.I) for f in fonts), \
                f"page {i + 1} has Chinese text but no CJK font: {sorted(fonts)}"
            return
    pytest.fail(f"逆序检验 not found on pages {start + 1}-{start + 4} (the opening of the time-series chapter)")
