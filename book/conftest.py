"""Strict nbval over the book's notebooks: which outputs are compared.

nbval compares every text output exactly and, by default, skips ``image/png``: a PNG's bytes
change with anti-aliasing and font hinting between machines while the figure does not.  Figures
stored with ``myst_nb.glue`` carry their PNG under the ``application/papermill.record/image/png``
key; they are skipped for the same reason, and nothing else is.

Once a cell has run, nbval waits at most 5 s for each of its output messages; a machine busy with
other work can deliver one later than that, and the cell would fail without its outputs having been
compared.  Here it waits up to :data:`OUTPUT_WAIT_S`: the wait ends with the cell's last message,
so a run on a quiet machine takes no longer.
"""

GLUED_IMAGES = ("application/papermill.record/image/png", "application/papermill.record/image/jpeg")

OUTPUT_WAIT_S = 120
"""Longest wait for each output message of a cell that has run (nbval's ``output_timeout``, 5 s by
default); how long a cell may run is ``--nbval-cell-timeout``."""


def pytest_collection_modifyitems(session, config, items):
    for item in items:
        parent = getattr(item, "parent", None)
        skip = getattr(parent, "skip_compare", None)
        if skip is not None and GLUED_IMAGES[0] not in skip:
            parent.skip_compare = tuple(skip) + GLUED_IMAGES
        if isinstance(getattr(item, "output_timeout", None), (int, float)):
            item.output_timeout = max(item.output_timeout, OUTPUT_WAIT_S)
