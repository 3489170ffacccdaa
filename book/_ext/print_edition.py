"""The reader's PDF in the HTML book: the landing page links it once ``make pdf`` has printed it.

``make pdf`` writes ``book/_build/pdf/book.pdf`` (scripts/book_pdf.py), beside the HTML build's
folder.  The role ``{print-edition}`words``` becomes a link to ``book.pdf`` when the HTML build
finds that file, which the build then copies into its output beside the landing page, so that the
link works offline and wherever the folder is copied; without the file the words stay plain (the
sentence around them says how to print it), so the HTML never carries a broken link.  The PDF is a
dependency of the page holding the role: the page is read again whenever the PDF is missing or
newer, so ``make pdf`` followed by ``make html`` links it.  The single-page build, from which the
PDF is printed, never links it.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from docutils import nodes

NAME = "book.pdf"
"""The PDF's name, in ``book/_build/pdf`` and in the HTML output."""


class PrintEdition(nodes.Inline, nodes.TextElement):
    """The words that link the PDF, resolved when a builder writes the page."""


def _pdf(app) -> Path:
    """Where ``make pdf`` writes the PDF: ``pdf/book.pdf`` beside the builder's output folder."""
    return Path(app.outdir).parent / "pdf" / NAME


def _role(name, rawtext, text, lineno, inliner, options=None, content=None):
    env = inliner.document.settings.env
    env.note_dependency(str(_pdf(env.app)))
    return [PrintEdition(rawtext, text)], []


def _links(app) -> bool:
    return app.builder.name == "html" and _pdf(app).is_file()


def _resolve(app, doctree, docname):
    for node in list(doctree.findall(PrintEdition)):
        text = node.astext()
        if _links(app):
            uri = "../" * docname.count("/") + NAME
            node.replace_self(nodes.reference(text, text, refuri=uri, classes=["print-edition"]))
        else:
            node.replace_self(nodes.literal(text, text))


def _copy(app, exception):
    if exception is None and _links(app):
        shutil.copy2(_pdf(app), Path(app.outdir) / NAME)


def setup(app):
    app.add_node(PrintEdition)
    app.add_role("print-edition", _role)
    app.connect("doctree-resolved", _resolve)
    app.connect("build-finished", _copy)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
