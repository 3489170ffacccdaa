"""The landing page links the reader's PDF once ``make pdf`` has printed it (book/_ext/print_edition.py).

A two-page Sphinx project stands in for the book: its HTML build sits in ``_build/html`` and the
PDF, when printed, in ``_build/pdf/book.pdf``, as ``make html`` and ``make pdf`` place them.
"""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _build(src: Path, builder: str = "html") -> Path:
    from sphinx.application import Sphinx
    from sphinx.util.docutils import docutils_namespace

    out = src / "_build" / builder
    with docutils_namespace():   # each build registers its nodes and roles afresh, as a new process would
        app = Sphinx(str(src), None, str(out), str(src / "_build" / ".doctrees"), builder, status=None, warning=None,
                     freshenv=False, warningiserror=True, confoverrides={"extensions": ["print_edition"]})
        app.build()
    return out


@pytest.fixture
def project(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT / "book" / "_ext"))
    (tmp_path / "conf.py").write_text("project = 'p'\n", encoding="utf-8")
    (tmp_path / "index.rst").write_text("Title\n=====\n\nThe printed book, :print-edition:`book.pdf`.\n\n"
                                        ".. toctree::\n\n   part/page\n", encoding="utf-8")
    (tmp_path / "part").mkdir()
    (tmp_path / "part" / "page.rst").write_text("Page\n====\n\nAgain :print-edition:`the PDF`.\n", encoding="utf-8")
    return tmp_path


def _pdf(project: Path) -> Path:
    pdf = project / "_build" / "pdf" / "book.pdf"
    pdf.parent.mkdir(parents=True, exist_ok=True)
    pdf.write_bytes(b"%PDF-1.4\n% printed\n")
    return pdf


def test_without_the_pdf_the_words_stay_plain(project):
    out = _build(project)
    html = (out / "index.html").read_text(encoding="utf-8")
    assert "book.pdf" in html and 'href="book.pdf"' not in html
    assert not (out / "book.pdf").exists()


def test_printing_then_building_links_and_copies_the_pdf(project):
    """``make html``, then ``make pdf``, then ``make html`` again: the second build reads the page
    again (the PDF is its dependency), links the PDF from it, relative to a page in a folder too,
    and copies the PDF beside the landing page."""
    _build(project)
    pdf = _pdf(project)
    out = _build(project)
    assert 'href="book.pdf"' in (out / "index.html").read_text(encoding="utf-8")
    assert 'href="../book.pdf"' in (out / "part" / "page.html").read_text(encoding="utf-8")
    assert (out / "book.pdf").read_bytes() == pdf.read_bytes()


def test_the_single_page_build_never_links_it(project):
    """The PDF is printed from the single-page build: it does not link to itself."""
    _pdf(project)
    out = _build(project, "singlehtml")
    html = (out / "index.html").read_text(encoding="utf-8")
    assert "book.pdf" in html and 'href="book.pdf"' not in html
    assert not (out / "book.pdf").exists()
