"""numpydoc sections rendered for functions, classes and modules only.

``sphinx.ext.napoleon`` turns the ``Parameters`` / ``Returns`` / ``Attributes`` sections of a
docstring into field lists.  For the docstring of a module constant, a class attribute or a
property it follows the Google convention instead: a first line ``type: description`` is read as
the type, so "Ellipsoidal heights (m) accepted by ...: ..." became an unresolved reference to a
class named "Ellipsoidal heights" under the nitpicky build.  numpydoc has no such convention (the
type of a constant is not written in its docstring), so here the docstrings of data, attributes
and properties stay the plain text they are; every other docstring goes through napoleon as
before.
"""

from __future__ import annotations

from sphinx.ext import napoleon

PLAIN = ("attribute", "data", "property")
"""The ``what`` of autodoc whose docstrings napoleon leaves unchanged."""


def process_docstring(app, what, name, obj, options, lines):
    """napoleon's ``autodoc-process-docstring`` handler, skipped for the kinds of :data:`PLAIN`.

    Parameters
    ----------
    app : sphinx.application.Sphinx
        The application.
    what : str
        autodoc's kind of the object ("function", "class", "data", ...).
    name : str
        Fully qualified name of the object.
    obj : object
        The object.
    options : dict
        The autodoc directive's options.
    lines : list of str
        The docstring's lines, changed in place.
    """
    if what in PLAIN:
        return
    napoleon._process_docstring(app, what, name, obj, options, lines)


def setup(app):
    """Load napoleon and put :func:`process_docstring` in place of its docstring handler.

    Parameters
    ----------
    app : sphinx.application.Sphinx
        The application.

    Returns
    -------
    metadata : dict
        Sphinx extension metadata (parallel-safe).
    """
    app.setup_extension("sphinx.ext.napoleon")
    for listener in list(app.events.listeners.get("autodoc-process-docstring", [])):
        if listener.handler is napoleon._process_docstring:
            app.disconnect(listener.id)
            app.connect("autodoc-process-docstring", process_docstring, priority=listener.priority)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
