"""Every figure's image described by its caption, not by its file name.

A figure glued from a notebook (``glue:figure``) is an image whose file name is a hash; HTML
writes that name as the image's ``alt`` text when none is given, so a screen reader, a text
browser or a failed image load shows ``../_images/f58b0d….png``.  After the glued outputs are
pasted (``doctree-resolved``), each image inside a captioned figure that has no ``alt`` of its own
receives the caption's first sentence ("Reproduction of Fig. 2: zeros (o) and poles (x) of …").
An explicit ``:alt:`` is kept.
"""

from __future__ import annotations

import re

from docutils import nodes

ABBREVIATIONS = {"fig", "figs", "eq", "eqs", "tab", "no", "cf", "e.g", "i.e", "ch", "sec", "vs", "approx", "resp", "al"}
"""Words whose period does not end a sentence ("Fig. 2", "eqs. (4)", "cf. Table 4-44")."""

_END = re.compile(r"[.!?。]\s+(?=[A-Z(\"'\u4e00-\u9fff])|[。！？]")
MAX_CHARS = 300
"""An alt text longer than this is cut at a word boundary with an ellipsis."""


def first_sentence(text: str) -> str:
    """The first sentence of ``text`` (whitespace collapsed): up to the first period, question
    or exclamation mark followed by a space and a capital, skipping the periods of
    :data:`ABBREVIATIONS`; at most :data:`MAX_CHARS` characters."""
    if not isinstance(text, str):
        raise TypeError(f"first_sentence: text must be a str, got {type(text).__name__}")
    text = " ".join(text.split())
    for m in _END.finditer(text):
        before = re.search(r"([\w.]+)$", text[: m.start()])
        if m.group(0)[0] == "." and before and before.group(1).lower() in ABBREVIATIONS:
            continue
        text = text[: m.start() + 1]
        break
    if len(text) > MAX_CHARS:
        text = text[:MAX_CHARS].rsplit(" ", 1)[0] + " …"
    return text


def _set_alt(app, doctree, docname):
    for fig in doctree.findall(nodes.figure):
        captions = [c for c in fig.findall(nodes.caption)]
        if not captions:
            continue
        alt = first_sentence(captions[0].astext())
        if not alt:
            continue
        for img in fig.findall(nodes.image):
            if not img.get("alt") or img.get("alt") == img.get("uri"):
                img["alt"] = alt


def setup(app):
    app.connect("doctree-resolved", _set_alt)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
