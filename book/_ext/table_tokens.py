"""Table cells break between words, never inside a number, a status word or an id.

A cell of a table of the book (the comparison tables, the register, the status page) is prose
around tokens that a reader reads and copies whole: numbers (``0.00011051871``, ``-1.5e-05``,
``2.8e-07``), dates, equation and table numbers (``(4-3)``, ``4-33``), ids
(``chen2019-table-4-33``) and status words (``not-reproduced``).  In the HTML builds every
whitespace-separated token of a table cell that holds a digit or is a status word is wrapped in
``<span class="nowrap">`` (``white-space: nowrap`` in ``_static/tables.css``); the other words
wrap as prose (at spaces, and after the hyphen of a compound word).  The tables that a notebook
displays as HTML (a data frame, a styled frame) get the same marks in the cells that hold text only
(:func:`protect_html`).  A table wider than the content
column then scrolls inside its own box (tests/test_book_browser.py measures both).  The printed edition (LaTeX) is left alone.
"""

from __future__ import annotations

import re

from docutils import nodes

_CJK = "\u3000-\u303f\u3400-\u4dbf\u4e00-\u9fff\uf900-\ufaff\uff00-\uffef"
TOKEN = re.compile(rf"[{_CJK}]+|[^\s{_CJK}]+")
"""A token: a run of characters between spaces, cut where Chinese begins or ends (a line breaks
between Chinese characters, so a Chinese sentence with a number in it is not one word: only
its non-Chinese runs holding a digit stay whole)."""

SKIP = ("execution-report",)
"""Tables that mark their own tokens (``_ext/execution_report.py``)."""


def status_words() -> frozenset[str]:
    """The status vocabulary of the registry (row and artifact statuses)."""
    from replication.registry import reproduction

    return frozenset(reproduction.STATUSES) | frozenset(reproduction.STATUS_COLOURS)


def protected(token: str, statuses: frozenset[str] = frozenset()) -> bool:
    """Whether ``token`` must stay on one line: it holds a digit or is a status word.

    Parameters
    ----------
    token : str
        A run of characters without white space.
    statuses : frozenset of str
        The status words (:func:`status_words`); punctuation around the token is ignored.

    Returns
    -------
    bool
    """
    if not isinstance(token, str):
        raise TypeError(f"token must be a str, not {type(token).__name__}")
    return any(c.isdigit() for c in token) or token.strip(".,;:()[]") in statuses


def split_text(text: str, statuses: frozenset[str] = frozenset()) -> list[tuple[str, bool]]:
    """``text`` cut into pieces, each marked whether it is a protected token (:func:`protected`).

    The pieces joined give ``text`` back; consecutive unprotected words and the spaces between
    them stay one piece.

    Parameters
    ----------
    text : str
    statuses : frozenset of str

    Returns
    -------
    list of (str, bool)
    """
    pieces: list[tuple[str, bool]] = []
    pos = 0
    for m in TOKEN.finditer(text):
        if protected(m.group(0), statuses):
            if m.start() > pos:
                pieces.append((text[pos:m.start()], False))
            pieces.append((m.group(0), True))
            pos = m.end()
    if pos < len(text):
        pieces.append((text[pos:], False))
    return pieces


HTML_CELL = re.compile(r"(<t[dh]\b[^>]*>)([^<]*)(</t[dh]>)")
"""A cell of an HTML table whose content is text only."""


def protect_html(html: str, statuses: frozenset[str] = frozenset()) -> str:
    """``html`` with the protected tokens of its text-only table cells wrapped in
    ``<span class="nowrap">`` (:func:`split_text`; the text is HTML-escaped already).

    Parameters
    ----------
    html : str
        HTML holding tables (a data frame's ``to_html``).
    statuses : frozenset of str

    Returns
    -------
    str
    """
    if not isinstance(html, str):
        raise TypeError(f"html must be a str, not {type(html).__name__}")

    def cell(m):
        pieces = split_text(m.group(2), statuses)
        body = "".join(f'<span class="nowrap">{t}</span>' if keep else t for t, keep in pieces)
        return m.group(1) + body + m.group(3)

    return HTML_CELL.sub(cell, html)


def _protect_cells(app, doctree, docname):
    if app.builder.format != "html":
        return
    statuses = status_words()
    entries = [e for t in doctree.findall(nodes.table) if not set(SKIP) & set(t["classes"])
               for e in t.findall(nodes.entry)]
    for entry in entries:
        for text in list(entry.findall(nodes.Text)):
            parent = text.parent
            if isinstance(parent, (nodes.literal, nodes.math, nodes.raw, nodes.FixedTextElement)):
                continue           # code (kept whole by the CSS), maths, raw HTML, literal blocks
            if isinstance(parent, nodes.inline) and "nowrap" in parent["classes"]:
                continue
            pieces = split_text(str(text), statuses)
            if not any(p for _, p in pieces):
                continue
            new = [nodes.inline(s, s, classes=["nowrap"]) if p else nodes.Text(s) for s, p in pieces]
            parent.replace(text, new)
    for raw in doctree.findall(nodes.raw):      # the HTML outputs of the notebooks
        if "text_html" in raw["classes"] and "html" in raw.get("format", "").split() and "<table" in raw.astext():
            raw[:] = [nodes.Text(protect_html(raw.astext(), statuses))]


def setup(app):
    app.connect("doctree-resolved", _protect_cells)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
