"""Recording a result: :func:`compare` turns a chapter's rows into ``tables/<id>.csv`` (long
format), ``.md``, ``.tex`` and a ``.json`` sidecar (the chapter's notebook digest, the seeds,
the package versions); :func:`refresh_exports` rewrites the Markdown and TeX forms of the stored
tables.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
from importlib import metadata
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

import pandas as pd

from replication._meta import __version__
from replication.registry import verdicts as _verdicts
from replication.registry.comparison import comparison_frame
from replication.registry.locations import paper_dir, project_root, tables_dir, validate_id
from replication.registry.markdown import _markdown
from replication.registry.reading import list_tables, read_table
from replication.registry.readings import readings_ledgers
from replication.registry.schema import STATUSES, TRACKED_PACKAGES, RegistryError
from replication.registry.tex import _latex

SIDECAR_IDENTITY = (
    "id", "title", "description", "source", "notebook", "notebook_digest", "paper_source", "paper_digest",
    "table_digest", "seeds", "status_counts", "generated_by", "main_reading", "main_reading_evidence",
    "readings", "ruled_out", "summary", "groups",
)
"""Sidecar fields that identify a table and its inputs; when all are unchanged on a rerun the
stored sidecar (commit, versions) is kept."""


def _package_versions() -> dict[str, str]:
    vers = {}
    for name in TRACKED_PACKAGES:
        try:
            vers[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            vers[name] = "absent"
    return vers


def _git_head(root: Path) -> str | None:
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=10, check=False
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _notebook_digest(root: Path, notebook: str | None) -> str | None:
    """Digest of a notebook's code-cell sources (outputs excluded)."""
    if not notebook:
        return None
    path = root / notebook
    if not path.exists():
        return None
    try:
        nb = json.loads(path.read_text(encoding="utf-8"))
        src = "\n\x00".join(
            "".join(c.get("source", "")) for c in nb.get("cells", []) if c.get("cell_type") == "code"
        )
    except (ValueError, OSError):
        return None
    return _sha256(src.encode())


def compare(
    table_id: str,
    rows: Iterable[Mapping[str, Any]] | pd.DataFrame,
    *,
    title: str,
    notebook: str,
    seeds: Mapping[str, int] | None = None,
    paper_source: str | None = None,
    description: str = "",
    main_reading: str = "",
    reading_evidence: str = "",
    readings: Sequence[str] | None = None,
    ruled_out: Mapping[str, str] | None = None,
    summary: str = "",
) -> pd.DataFrame:
    """Compare reproduced with paper values and export ``tables/<table_id>.*``.

    The one call through which a chapter records a result.  ``rows`` as in
    :func:`~replication.registry.comparison.comparison_frame`; ``notebook`` is the chapter's path relative to the repository
    root; ``seeds`` the random seeds used; ``paper_source`` the ``data/paper`` file (defaults to
    the one named like ``table_id`` when it exists).  Writes ``.csv`` (long format), ``.md``,
    ``.tex`` and a ``.json`` sidecar; returns the comparison table.

    The verdict layer (CONTRIBUTING.md, "Readings and the main reading"): where the text leaves
    a choice open or two printed parts disagree, ``main_reading`` names the reading the table
    follows and ``reading_evidence`` says, in one sentence, which printed numbers support it;
    ``readings`` names the readings ledgers (default: ``<key>-check-<rest>-readings`` when it is
    exported, see :func:`~replication.registry.readings.readings_ledgers`); ``ruled_out`` maps a reading of a ledger (or the
    prefix shared by several) to the printed evidence that excludes it — the only way a
    ``not-reproduced`` or ``erratum`` row may stand beside a reading that reproduces it
    (:func:`~replication.registry.readings.verdict_violations`).  ``summary`` is the table's verdict in one line, quoted by the
    roll-ups (:func:`~replication.registry.tallies.failing_artifacts`).  All five are stored in the sidecar when given.

    Writing is idempotent: when the table and its inputs are unchanged the files are not
    touched, so re-running a chapter leaves ``git status`` clean.  The sidecar's ``git_commit`` is
    the commit on top of which the values were last (re)computed.

    Parameters
    ----------
    table_id : str
        The id of the exported table (:func:`~replication.registry.locations.validate_id`).
    rows : iterable of mappings or pandas.DataFrame
        The compared quantities (:func:`~replication.registry.comparison.comparison_frame`).
    title : str
        The table's title (caption of the exports, title of the citation).
    notebook : str
        The chapter that computes it, relative to the repository root.
    seeds : mapping of str to int, optional
        The random seeds used.
    paper_source : str, optional
        The ``data/paper`` file, relative to the root.
    description : str, optional
        A longer description for the sidecar.
    main_reading : str, optional
        The reading the table follows (with ``reading_evidence``).
    reading_evidence : str, optional
        The printed numbers that support the main reading, in one sentence.
    readings : str or sequence of str, optional
        The readings ledgers' table ids.
    ruled_out : mapping of str to str, optional
        Reading (or prefix) to the printed evidence that excludes it.
    summary : str, optional
        The table's verdict in one line.

    Returns
    -------
    pandas.DataFrame
        The comparison table (:func:`~replication.registry.comparison.comparison_frame`), with ``attrs`` ``table_id`` and
        ``notebook`` (so that :func:`~replication.registry.markdown.display_table` links it).
    """
    validate_id(table_id)
    if bool(main_reading) != bool(reading_evidence):
        raise RegistryError(f"{table_id}: give main_reading and reading_evidence together (the reading and the "
                            "printed numbers that support it)")
    for name, text in (("main_reading", main_reading), ("reading_evidence", reading_evidence), ("summary", summary)):
        if not isinstance(text, str):
            raise RegistryError(f"{table_id}: {name} must be a string, not {type(text).__name__}")
    ledgers = [] if readings is None else [validate_id(t) for t in ([readings] if isinstance(readings, str) else readings)]
    ruled = {}
    for k, v in dict(ruled_out or {}).items():
        if not (isinstance(k, str) and k.strip() and isinstance(v, str) and v.strip()):
            raise RegistryError(f"{table_id}: ruled_out maps a reading to the printed evidence excluding it "
                                f"(two non-empty strings), not {k!r}: {v!r}")
        ruled[k] = v
    if isinstance(rows, pd.DataFrame):
        rows = rows.to_dict("records")
    rows = [dict(r) for r in rows]
    grouped: dict[str, list[str]] = {}
    for r in rows:
        g = r.pop("group", None)
        if g not in (None, ""):
            grouped.setdefault(str(g), []).append(str(r.get("quantity")))
    df = comparison_frame(rows, table_id)
    if (df["basis"] != "").any() and (ledgers or readings_ledgers(table_id, {})):
        from replication.registry import audit as _audit  # reads the exported ledgers

        meta = {"main_reading": main_reading, "ruled_out": ruled, "groups": grouped}
        readings_rows = _audit._ledger_rows(ledgers or readings_ledgers(table_id, {}))
        for i, r in df.iterrows():
            if r["basis"] in ("value", "verdict", "derivation") and r["status"] in ("not-reproduced", "erratum"):
                led = _audit.ledger_evidence(r["quantity"], df, meta, readings_rows)
                if led.reaching:
                    df.loc[i, "status"] = _verdicts.after_ledger(
                        led, "not-reproduced" if r["status"] == "not-reproduced" else "erratum")
    root = project_root()
    out_dir = tables_dir()
    out_dir.mkdir(parents=True, exist_ok=True)
    if paper_source is None:
        key = table_id.split("-", 1)[0]
        cand = paper_dir() / key / f"{table_id}.csv"
        paper_source = str(cand.relative_to(root)) if cand.exists() else None
    paper_digest = None
    if paper_source:
        pth = root / paper_source
        if not pth.exists():
            raise RegistryError(f"paper_source {paper_source!r} does not exist")
        paper_digest = _sha256(pth.read_bytes())
    csv_text = df.to_csv(index=False, lineterminator="\n")
    counts = {s: int((df["status"] == s).sum()) for s in STATUSES}
    sidecar = {
        "id": table_id,
        "title": title,
        "description": description,
        "source": table_id.split("-", 1)[0],
        "notebook": notebook,
        "notebook_digest": _notebook_digest(root, notebook),
        "paper_source": paper_source,
        "paper_digest": paper_digest,
        "table_digest": _sha256(csv_text.encode()),
        "library_version": __version__,
        "packages": _package_versions(),
        "seeds": dict(seeds or {}),
        "status_counts": counts,
        "generated_by": "replication.registry.reproduction.compare",
    }
    for key, value in (("main_reading", main_reading), ("main_reading_evidence", reading_evidence),
                       ("readings", ledgers), ("ruled_out", ruled), ("summary", summary), ("groups", grouped)):
        if value:
            sidecar[key] = value
    json_path = out_dir / f"{table_id}.json"
    old = None
    if json_path.exists():
        try:
            old = json.loads(json_path.read_text(encoding="utf-8"))
        except ValueError:
            old = None
    same = (old is not None and (out_dir / f"{table_id}.csv").exists()
            and all(old.get(k) == sidecar.get(k) for k in SIDECAR_IDENTITY))
    if same:
        # the same table from the same inputs: its provenance (the commit, library and package
        # versions that first produced it) stands, so a rerun on another machine changes nothing
        sidecar = old
    else:
        sidecar["git_commit"] = _git_head(root)
    files = {
        ".csv": csv_text,
        ".md": _markdown(df, title),
        ".tex": _latex(df, title, table_id),
        ".json": json.dumps(sidecar, indent=2, sort_keys=True) + "\n",
    }
    for ext, content in files.items():
        p = out_dir / f"{table_id}{ext}"
        if not p.exists() or p.read_text(encoding="utf-8") != content:
            p.write_text(content, encoding="utf-8")
    df.attrs.update(table_id=table_id, notebook=notebook)
    return df


def refresh_exports(table_ids: Iterable[str] | None = None) -> list[str]:
    """Rewrite the ``.md`` and ``.tex`` exports of tables from their stored CSV and sidecar title,
    without recomputing anything (after a change of the export format).  Returns the ids whose
    files changed; the CSV and the sidecar are left as they are.

    Parameters
    ----------
    table_ids : iterable of str, optional
        The tables to refresh; every exported table by default.

    Returns
    -------
    list of str
        The ids whose ``.md`` or ``.tex`` changed.
    """
    project_root()                      # only a clone is written to: refuses outside one
    changed = []
    for tid in list_tables() if table_ids is None else list(table_ids):
        df = read_table(tid)
        title = json.loads((tables_dir() / f"{tid}.json").read_text(encoding="utf-8"))["title"]
        touched = False
        for ext, content in ((".md", _markdown(df, title)), (".tex", _latex(df, title, tid))):
            p = tables_dir() / f"{tid}{ext}"
            if not p.exists() or p.read_text(encoding="utf-8") != content:
                p.write_text(content, encoding="utf-8")
                touched = True
        if touched:
            changed.append(tid)
    return changed
