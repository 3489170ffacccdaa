"""The reproduction registry: paper values in, citable comparison tables out.

This module is the one way a chapter records a result; it gathers the names of the registry's
modules, one concept each, so that a chapter imports one module
(``from replication.registry import reproduction as rp``):

* :mod:`~replication.registry.schema` — the status vocabulary, the table columns, the error;
* :mod:`~replication.registry.locations` — where the clone, the data and the tables live, and table ids;
* :mod:`~replication.registry.paper` — the paper values of ``data/paper/`` with their provenance;
* :mod:`~replication.registry.digits` — the precision policy: stored digits and displayed numbers;
* :mod:`~replication.registry.comparison` — the comparison and status rule of one row;
* :mod:`~replication.registry.exports` — :func:`~replication.registry.exports.compare` and the four
  export formats of a table (CSV, Markdown, TeX, JSON sidecar);
* :mod:`~replication.registry.markdown` and :mod:`~replication.registry.tex` — the Markdown and TeX forms;
* :mod:`~replication.registry.reading` — the read side: stored tables, sidecars, the artifact list, ids;
* :mod:`~replication.registry.readings` — the readings ledgers and the verdict rule's entry points;
* :mod:`~replication.registry.tallies` — an artifact's status and the tallies of statuses;
* :mod:`~replication.registry.links` — links from the status pages into the chapters;
* :mod:`~replication.registry.boxes` — the findings boxes of the chapters and the papers' summaries;
* :mod:`~replication.registry.datapackage` — the Frictionless data package of ``tables/``;
* :mod:`~replication.registry.register` — the register of errata and inconsistencies;
* :mod:`~replication.registry.index` — the index: ``tables/status.csv`` and the status page;
* :mod:`~replication.registry.cite` — BibTeX for a table, an artifact or a source.

In short:

* Paper values live in ``data/paper/<key>/<id>.csv``.  Each file starts with ``#`` provenance
  lines (``# document: chen2019`` ...) followed by a CSV body with at least the columns
  ``quantity, unit, value``.  :func:`~replication.registry.paper.load_paper` reads and validates one.
* A chapter compares its computed values with the paper's through
  :func:`~replication.registry.exports.compare`, which writes ``tables/<id>.csv`` (long format),
  ``.md``, ``.tex`` and a ``.json`` sidecar.
* :func:`~replication.registry.index.build_index` aggregates every exported table into
  ``tables/status.csv`` (one row per reproducible artifact listed in ``data/artifacts.csv``) and
  ``tables/register.csv`` (every row whose status is ``erratum`` or ``inconsistent``, with its
  ``kind``), after checking the verdict rule (:func:`~replication.registry.readings.verdict_violations`):
  no ``not-reproduced`` or ``erratum`` row that a reading of its table's readings ledger
  reproduces, unless the table names the printed evidence that rules that reading out.

Status vocabulary (:data:`~replication.registry.schema.STATUSES`):

``reproduced``      within a tolerance stated before comparing;
``erratum``         the printed value is proven wrong and the corrected value is reproduced;
``qualitative``     ordering / shape / sign reproduced, magnitudes not comparable (reason stated);
``analog``          the paper used unpublished data; a labelled simulation stands in;
``not-reproduced``  tried, differs, with an honest reason;
``pending``         not reached yet.
"""

# ruff: noqa: F401
from __future__ import annotations

from replication._meta import __version__, repository_url
from replication.registry.boxes import (
    FINDING_REASON_STATUSES,
    _failing_markdown,
    _findings_markdown,
    _paper_summary_markdown,
    _row_split,
    findings_file,
)
from replication.registry.cite import (
    PACKAGE_YEAR,
    _table_bibtex,
    bibtex_for,
    source_bibtex,
)
from replication.registry.comparison import (
    _derive,
    _row_errors,
    _text_or_number,
    comparison_frame,
)
from replication.registry.datapackage import (
    _COUNT,
    DATAPACKAGE,
    FIELD_DESCRIPTIONS,
    FIELD_UNITS,
    REGISTER_FIELD_DESCRIPTIONS,
    STATUS_FIELD_DESCRIPTIONS,
    _field,
    _field_type,
    datapackage,
    write_datapackage,
)
from replication.registry.digits import (
    DEFAULT_DIGITS,
    DISPLAY_DIGITS,
    ERROR_DIGITS,
    TOLERANCE_DIGITS,
    TRANSCRIBED_DIGITS,
    _as_float_or_nan,
    _as_number,
    _display_digits,
    _display_float,
    _fmt,
    _is_nan_text,
    _row_grid,
    _significant,
    _store,
    _store_paper,
    display_cell,
    display_number,
    format_number,
    round_sig,
    round_to_grid,
    tolerance_grid,
)
from replication.registry.exports import (
    SIDECAR_IDENTITY,
    _git_head,
    _notebook_digest,
    _package_versions,
    _sha256,
    compare,
    refresh_exports,
)
from replication.registry.index import (
    _criteria_markdown,
    _status_markdown,
    _status_row,
    build_index,
)
from replication.registry.links import (
    _chapter_link,
    _notebook_targets,
    _table_links,
)
from replication.registry.locations import (
    PACKAGED_DATA,
    _clone_root,
    _is_clone,
    _write_if_changed,
    data_root,
    paper_dir,
    project_root,
    tables_dir,
    validate_id,
)
from replication.registry.markdown import (
    _HEADINGS,
    COMPACT_COLUMNS,
    _markdown,
    _md_comparison,
    _md_table,
    display_table,
)
from replication.registry.paper import (
    PaperTable,
    load_paper,
    parse_paper_file,
)
from replication.registry.reading import (
    READ_COLUMNS,
    SIDECAR_KEYS,
    SIDECAR_OPTIONAL,
    _artifact_ids,
    _digest_problem,
    _known_ids,
    _near_ids,
    _no_tables_dir,
    _read_csv,
    _sidecar,
    _unknown_id,
    artifact_tables,
    list_tables,
    load_artifacts,
    load_table,
    load_tables,
    read_table,
    resolve_table_id,
    resolve_table_ids,
)
from replication.registry.readings import (
    READING_SEPARATOR,
    check_verdicts,
    readings_ledgers,
    verdict_violations,
)
from replication.registry.register import (
    REGISTER_COLUMNS,
    _formula,
    _register_markdown,
    build_register,
)
from replication.registry.schema import (
    _ID_RE,
    NUMERIC_COLUMNS,
    REQUIRED_PROVENANCE,
    ROW_KEYS,
    SOURCE_KEYS,
    STATUSES,
    TABLE_COLUMNS,
    TRACKED_PACKAGES,
    RegistryError,
)
from replication.registry.tallies import (
    ARTIFACT_STATUSES,
    STATUS_COLOURS,
    _first_clause,
    failing_artifacts,
    status_bar_html,
    status_label,
    status_tally,
    summarize_status,
)
from replication.registry.tex import (
    _BREAK,
    _GREEK,
    _LONG_TOKEN,
    _MATH_SIGNS,
    _TEX_ACCENTS,
    _TEX_LIGATURES,
    _TEX_PACKAGE_SOURCES,
    _TEX_SPECIAL,
    _TEX_TEXT_ACCENTS,
    _TEX_UNICODE,
    TEX_CJK_FONT,
    TEX_COLUMNS,
    TEX_EXTRA_PACKAGES,
    TEX_PACKAGES,
    _is_cjk,
    _latex,
    _tex_breakable,
    _tex_cell,
    _tex_char,
    _tex_escape,
    tex_packages,
)
