"""The registry's vocabulary: the statuses, the source keys, the columns of a comparison table and
of a paper-value file, the form of a table id, and the error every malformed input raises.
"""

from __future__ import annotations

import re

STATUSES = (
    "reproduced", "erratum", "inconsistent", "qualitative", "analog", "unverifiable", "not-reproduced", "pending",
)
"""The status vocabulary, in the order used for summaries (best first)."""


SOURCE_KEYS = ("chen2019", "fang2020", "duan2023", "an2021")
"""Citation keys of the four source documents."""


REQUIRED_PROVENANCE = ("document", "location", "section", "notes")
"""Provenance fields every paper-value file must carry."""


TABLE_COLUMNS = (
    "quantity", "unit", "paper", "paper_text", "reproduced", "reproduced_text", "abs_error", "rel_error",
    "tolerance", "tolerance_kind", "status", "note", "evidence", "corrected", "basis", "agrees", "rests_on",
)
"""Columns of every exported comparison table, in order.  ``paper``, ``reproduced``,
``abs_error``, ``rel_error`` and ``tolerance`` hold numbers only (or nothing); the printed form
of a non-numeric paper value is in ``paper_text``, a non-numeric result in ``reproduced_text``."""


NUMERIC_COLUMNS = ("paper", "reproduced", "abs_error", "rel_error", "tolerance")
"""The numeric columns of :data:`TABLE_COLUMNS`."""


ROW_KEYS = (
    "quantity", "unit", "paper", "paper_text", "reproduced", "tolerance", "tolerance_kind", "status",
    "note", "evidence", "corrected", "digits", "basis", "agrees", "rests_on",
)
"""Keys a comparison row may carry (see :func:`~replication.registry.comparison.comparison_frame`)."""


TRACKED_PACKAGES = (
    "numpy", "scipy", "pandas", "statsmodels", "control", "matplotlib", "sympy", "numba",
)


_ID_RE = re.compile(r"^(chen2019|fang2020|duan2023|an2021|toolkit)-(table|figure|eq|claim|check|print)-[0-9a-z][0-9a-z.-]*$")


class RegistryError(ValueError):
    """A paper-value file, a table id or a comparison row is malformed."""
