"""The printed book (``make pdf``): one PDF for readers that opens, with every chapter, text on
its pages, the sources' Chinese terms in a CJK font, and maths typeset; a title page naming the
version, the date and the repository; numbered contents whose page numbers are the pages their
entries lead to; no module page of the library reference; every link leading into the book or to
the repository, none to the machine that printed it; and a size that stays small.

Run after ``make pdf`` (``make test`` runs it after the strict build and the browser check): the
PDF is ``book/_build/pdf/book.pdf``, printed by scripts/book_pdf.py from the single-page build.
Text is read from a sample of pages (the title page, the contents, the opening pages of the
time-series chapter, the register); links and bookmarks from every page, so the check takes seconds.
"""

from __future__ import annotations

import datetime
import re
import unicodedata
from pathlib import Path
from urllib.parse import urlparse

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
    """Without spaces and ligatures (the PDF's text has "ﬁ" where the HTML has "fi")."""
    return re.sub(r"\s+", "", unicodedata.normalize("NFKC", s))


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


def _text(page) -> str:
    return " ".join((page.extract_text() or "").split())


def test_the_title_page_names_version_date_and_repository(reader):
    """Title, authors (CITATION.cff), ``replication <version>``, the date it was printed (the
    PDF's creation date, UTC) and the repository address, on the first page."""
    import yaml

    from replication import __version__, repository_url

    text = _text(reader.pages[0])
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    for author in cff["authors"]:
        assert author["name"] in text, f"author {author['name']!r} not on the title page: {text[:300]!r}"
    assert f"replication {__version__}" in text, f"no version {__version__} on the title page: {text[:300]!r}"
    assert repository_url() in text.replace(" ", ""), f"no {repository_url()} on the title page: {text!r}"
    created = str(reader.metadata["/CreationDate"])            # D:YYYYMMDDHHmmSS+HH'mm'
    day = datetime.datetime.strptime(created[2:16], "%Y%m%d%H%M%S")
    offset = re.match(r"([+-])(\d\d)'(\d\d)", created[16:].replace("Z", "+00'00"))
    if offset:
        sign = 1 if offset.group(1) == "+" else -1
        day -= sign * datetime.timedelta(hours=int(offset.group(2)), minutes=int(offset.group(3)))
    printed = re.findall(r"Printed (\d{4}-\d\d-\d\d)", text)
    assert printed, f"no 'Printed <date>' on the title page: {text!r}"
    # the date is taken just before Chromium prints: the same UTC day, or the day before at midnight
    assert printed[0] in {day.date().isoformat(), (day - datetime.timedelta(days=1)).date().isoformat()}, \
        f"the title page says printed {printed[0]}, the PDF was created {day:%Y-%m-%d %H:%M} UTC"


def _fragments(page) -> list[tuple[float, float, str]]:
    """(x, y, text) of every piece of text on a page, in the page's default coordinates."""
    out = []

    def visit(text, cm, tm, font, size):
        if text.strip():
            out.append((tm[4] * cm[0] + tm[5] * cm[2] + cm[4], tm[4] * cm[1] + tm[5] * cm[3] + cm[5], text.strip()))

    page.extract_text(visitor_text=visit)
    return out


def test_the_contents_give_each_entry_the_page_it_leads_to(reader, outline):
    """The contents (from the page bookmarked "Contents" to the book's first heading) list every
    chapter; each entry is a link into the book, and the number printed at its right end is the
    page (as the page footers count) the link leads to."""
    start, body = _page(outline, "Contents"), _page(outline, "Reproducing SINS/GNSS research")
    assert 0 < start < body <= 10, f"contents on pages {start + 1}-{body} of the PDF"
    named = reader.named_destinations
    checked, text = 0, ""
    for i in range(start, body):
        page = reader.pages[i]
        text += _text(page) + " "
        frags = _fragments(page)
        for annot in page.get("/Annots") or []:
            a = annot.get_object()
            dest = a.get("/Dest")
            if dest is None:
                continue
            x0, y0, x1, y1 = (float(v) for v in a["/Rect"])
            numbers = [(x, t) for x, y, t in frags if x0 - 1 <= x <= x1 + 1 and y0 - 1 <= y <= y1 + 1 and t.isdigit()]
            if not numbers:      # the second line of a wrapped entry: its number is on the first
                continue
            printed = int(max(numbers)[1])
            assert str(dest) in named, f"contents entry on page {i + 1} leads to {dest}, which the PDF does not define"
            target = reader.get_destination_page_number(named[str(dest)]) + 1
            assert printed == target, f"contents entry on page {i + 1} ({dest}) says page {printed}, leads to page {target}"
            checked += 1
    chapters = _chapters()
    missing = [c for c in chapters if _squash(re.sub(r"^\d+\.\s*", "", c)) not in _squash(text)]
    assert not missing, f"chapters missing from the contents: {missing}"
    assert checked > len(chapters), f"only {checked} contents entries carry a page number"


def _api_modules() -> list[str]:
    """The modules of the library reference's module pages (``book/appendix/api/*.md``)."""
    return sorted(m for p in (ROOT / "book" / "appendix" / "api").glob("*.md")
                  for m in re.findall(r"automodule::\s*(\S+)", p.read_text(encoding="utf-8")))


def test_the_library_reference_modules_are_not_printed(reader, outline):
    """The print keeps the chapter "Library reference" (its overview) and says that the module
    pages are left out; no bookmark (a heading) is a module page's."""
    modules = _api_modules()
    assert len(modules) >= 20, f"only {len(modules)} module pages found under book/appendix/api"
    headings = {t for t, _ in outline}
    printed = sorted(m for m in modules if any(_squash(m) in _squash(t) for t in headings))
    assert not printed, f"module pages of the library reference in the PDF: {printed}"
    i = _page(outline, "Library reference")
    assert "not printed" in _text(reader.pages[i]), f"page {i + 1} does not say the module pages are left out"


def test_every_link_leads_into_the_book_or_to_the_repository(reader):
    """No link points to the machine that printed the book (127.0.0.1, localhost, a file); every
    link within the book names a destination the PDF defines; every link into the repository
    (``<repository>/blob/<commit>/<path>``) names a file the repository holds, and the tables'
    CSV files are among them."""
    from replication import repository_url

    blob = re.compile(re.escape(repository_url().rstrip("/")) + r"/blob/(?:[0-9a-f]{40}|main)/([^#?]+)")
    named = reader.named_destinations
    local, dangling, missing, files = [], set(), set(), set()
    for i, page in enumerate(reader.pages):
        for annot in page.get("/Annots") or []:
            a = annot.get_object()
            if a.get("/Subtype") != "/Link":
                continue
            if a.get("/Dest") is not None:
                if str(a["/Dest"]) not in named:
                    dangling.add(str(a["/Dest"]))
                continue
            uri = str((a.get("/A") or {}).get("/URI", ""))
            host = urlparse(uri).hostname or ""
            if uri.startswith("file:") or host in {"127.0.0.1", "localhost", "0.0.0.0", "::1"}:
                local.append(f"page {i + 1}: {uri}")
            m = blob.match(uri)
            if m:
                files.add(m.group(1))
                if not (ROOT / m.group(1)).exists():
                    missing.add(m.group(1))
    assert not local, f"{len(local)} links to the printing machine: {local[:5]}"
    assert not dangling, f"links to destinations the PDF does not define: {sorted(dangling)[:5]}"
    assert not missing, f"links to files the repository does not hold: {sorted(missing)[:5]}"
    tables = {f for f in files if re.fullmatch(r"tables/[^/]+\.csv", f)}
    assert len(tables) >= 50, f"only {len(tables)} tables linked in the repository"


def test_the_pdf_stays_small(reader):
    """Untagged and without shadows printed as page-sized soft masks, the PDF holds about 16 kB a
    page; a structure tree (about 58 kB a page) or rasterised shadows (37) would exceed 30."""
    per_page = PDF.stat().st_size / len(reader.pages)
    assert per_page < 30_000, f"{per_page / 1e3:.0f} kB a page ({PDF.stat().st_size / 1e6:.1f} MB)"


def test_the_readme_states_the_pdf_a_reader_gets(reader):
    """The README's page count and size describe the printed PDF: within a tenth in pages and a
    fifth in bytes (chapters grow by a row or a paragraph between releases; a larger change means
    the README must be updated)."""
    text = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    m = re.search(r"`make pdf` prints the book for readers from the stored outputs, offline: (\d+) pages, "
                  r"([\d.]+) MB", text)
    assert m, "README.md no longer states the PDF's page count and size after 'make pdf prints the book'"
    pages, mb = int(m.group(1)), float(m.group(2))
    n, size = len(reader.pages), PDF.stat().st_size / 1e6
    assert abs(n - pages) <= 0.1 * pages, f"README says {pages} pages, the PDF has {n}: update README.md"
    assert abs(size - mb) <= 0.2 * mb, f"README says {mb} MB, the PDF holds {size:.1f} MB: update README.md"
