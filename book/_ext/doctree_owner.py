"""Every node of a page's doctree owned by the page's own document before Sphinx pickles it.

Directives that parse text into a document of their own (autodoc's docstrings inside MyST's
``eval-rst``, myst-nb's glue) leave the nodes they return pointing at that document, and so at its
settings, which hold the whole build environment: pickled with the page, it made each library
reference page's doctree about 0.9 MB whatever the page held (62 MB for the book, 51 MB of them
the library reference), and reading them back was most of the single-page build of the PDF.
Pointing the nodes at the page's document changes nothing rendered.
"""

from __future__ import annotations


def own_nodes(app, doctree) -> int:
    """Point every node of ``doctree`` whose document is another one at ``doctree``.

    Parameters
    ----------
    app : sphinx.application.Sphinx
        The application (unused).
    doctree : docutils.nodes.document
        The page just read.

    Returns
    -------
    int
        How many nodes were pointed at the page's document.
    """
    moved = 0
    for node in doctree.findall():
        if node.__dict__.get("_document", doctree) is not doctree:
            node.document = doctree
            moved += 1
    return moved


def setup(app):
    """Connect :func:`own_nodes` to ``doctree-read``, after the other handlers.

    Parameters
    ----------
    app : sphinx.application.Sphinx
        The application.

    Returns
    -------
    metadata : dict
        Sphinx extension metadata (parallel-safe).
    """
    app.connect("doctree-read", own_nodes, priority=900)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
