"""Strict nbval over the book's notebooks: which outputs are compared.

nbval compares every text output exactly and, by default, skips ``image/png``: a PNG's bytes
change with anti-aliasing and font hinting between machines while the figure does not.  Figures
stored with ``myst_nb.glue`` carry their PNG under the ``application/papermill.record/image/png``
key; they are skipped for the same reason, and nothing else is.
"""

GLUED_IMAGES = ("application/papermill.record/image/png", "application/papermill.record/image/jpeg")


def pytest_collection_modifyitems(session, config, items):
    for item in items:
        parent = getattr(item, "parent", None)
        skip = getattr(parent, "skip_compare", None)
        if skip is not None and GLUED_IMAGES[0] not in skip:
            parent.skip_compare = tuple(skip) + GLUED_IMAGES
