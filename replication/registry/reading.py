"""The read side of the registry: a stored table and its sidecar, the list of exported tables, the
artifact list ``data/artifacts.csv``, the resolution of an id (a table, a multi-table artifact)
with near-miss suggestions, and the typed loaders :func:`load_table` and :func:`load_tables`.
"""

from __future__ import annotations

import difflib
import functools
import hashlib
import io
import json
import os
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import pandas as pd

from replication.registry.locations import data_root, tables_dir, validate_id
from replication.registry.schema import _ID_RE, NUMERIC_COLUMNS, RegistryError


def read_table(table_id: str) -> pd.DataFrame:
    """An exported comparison table (``tables/<id>.csv``) as text columns.

    Parameters
    ----------
    table_id : str
        An exported table id.

    Returns
    -------
    pandas.DataFrame
        ``tables/<id>.csv`` with every column as text (empty cells as ``""``).

    Raises
    ------
    RegistryError
        No such exported table (the message lists those of the same source).
    """
    validate_id(table_id)
    path = tables_dir() / f"{table_id}.csv"
    if not path.exists():
        raise RegistryError(_unknown_id(table_id))
    df = _read_csv(path, "re-run the notebook that exports it, or restore it from the repository (git checkout)")
    missing = [c for c in READ_COLUMNS if c not in df.columns]
    if missing:
        raise RegistryError(f"{path}: not a comparison table: it lacks the columns {missing}; re-run the notebook "
                            "that exports it, or restore it from the repository (git checkout)")
    return df


READ_COLUMNS = ("quantity", "unit", "paper", "reproduced", "status")
"""The columns of :data:`~replication.registry.schema.TABLE_COLUMNS` every reader relies on; :func:`read_table` refuses a CSV without them."""


def _read_csv(path: Path, fix: str, comment: str | None = None) -> pd.DataFrame:
    """``path`` read as text columns; a file that is empty, not CSV or not UTF-8 raises :class:`~replication.registry.schema.RegistryError`
    naming it and ``fix``.  The parse is kept per content (:func:`csv_text_frame`): the audit of
    ``index`` reads most tables several times, and an unchanged file is parsed once."""
    try:
        return csv_text_frame(Path(path).read_bytes(), comment).copy()
    except pd.errors.EmptyDataError:
        why = "is empty"
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        why = f"is not a readable UTF-8 CSV file ({str(exc).splitlines()[0][:120]})"
    except OSError as exc:
        why = f"cannot be read ({exc.strerror or exc})"
    raise RegistryError(f"{path} {why}: {fix}")


@functools.lru_cache(maxsize=1024)
def csv_text_frame(content: bytes, comment: str | None = None) -> pd.DataFrame:
    """The CSV ``content`` (UTF-8) as text columns, empty cells as ``""``: parsed once per content
    (the key is the bytes themselves, so a copy of a file, or a file rewritten with the same bytes,
    is not parsed again, and an edited one always is).  Callers copy the frame before changing it.

    Parameters
    ----------
    content : bytes
        The file's bytes.
    comment : str or None
        A character that starts a comment line (``pandas.read_csv``'s ``comment``).

    Returns
    -------
    pandas.DataFrame
        Shared between the callers with the same content: not to be changed in place.

    Raises
    ------
    TypeError
        ``content`` is not bytes (read the file with ``Path.read_bytes()``).
    """
    if not isinstance(content, bytes):
        raise TypeError(f"content must be the file's bytes (Path.read_bytes()), got {type(content).__name__}")
    return pd.read_csv(io.BytesIO(content), dtype=str, keep_default_na=False, encoding="utf-8", comment=comment)


def _known_ids() -> list[str]:
    """Every id the read side answers to: the exported tables and the artifacts of ``data/artifacts.csv``."""
    return sorted(set(list_tables()) | _artifact_ids())


def _artifact_ids() -> set[str]:
    """The ids of ``data/artifacts.csv`` (none when it cannot be read: its own reader names the problem)."""
    try:
        return set(load_artifacts()["id"])
    except RegistryError:
        return set()


def _near_ids(ident: str) -> list[str]:
    """The known ids nearest to ``ident`` (at most five, by ``difflib``; case and spaces ignored)."""
    known = [k for k in _known_ids() if k != ident]         # never the id typed (a table without its CSV)
    return (difflib.get_close_matches(ident, known, n=5, cutoff=0.6)
            or difflib.get_close_matches(ident.strip().lower(), known, n=5, cutoff=0.6))


def _unknown_id(ident: str) -> str:
    """The message for an id that names no table: the nearest known ids (at most five), or where to find them."""
    if not tables_dir().is_dir():
        return f"no exported table {ident!r}: {_no_tables_dir()}"
    near = _near_ids(ident)
    hint = f"did you mean {', '.join(near)}?" if near else "no known id is close to it;"
    return f"no exported table {ident!r}: {hint} (python -m replication status lists every id)"


def _no_tables_dir() -> str:
    """The message for a missing ``tables/``: where it was looked for and what to do."""
    env = os.environ.get("REPLICATION_ROOT")
    where = f" (REPLICATION_ROOT={env})" if env else ""
    return (f"{tables_dir()} does not exist{where}: restore it (git checkout -- tables), run inside a clone of the "
            "repository, or set REPLICATION_ROOT to its root")


def list_tables() -> list[str]:
    """The ids of the exported tables (those with a sidecar in ``tables/``).

    Returns
    -------
    list of str
        Sorted table ids; empty when ``tables/`` does not exist.
    """
    d = tables_dir()
    return sorted(p.stem for p in d.glob("*.json") if _ID_RE.match(p.stem)) if d.exists() else []


def load_artifacts() -> pd.DataFrame:
    """The list of reproducible artifacts of every seed (``data/artifacts.csv``).

    Returns
    -------
    pandas.DataFrame
        Columns ``id``, ``source``, ``artifact``, ``description`` (and ``tables`` where given), as text.

    Raises
    ------
    RegistryError
        A missing column, a malformed or duplicated id.
    """
    path = data_root() / "data" / "artifacts.csv"
    if not path.is_file():
        env = os.environ.get("REPLICATION_ROOT")
        hint = (f"REPLICATION_ROOT={env} is not the root of a clone: set it to the clone (the folder holding "
                "tables/ and data/), or unset it" if env and not (path.parents[1] / "tables").is_dir()
                else "restore it from the repository (git checkout data/artifacts.csv)")
        raise RegistryError(f"{path} does not exist: {hint}")
    df = _read_csv(path, "restore it from the repository (git checkout data/artifacts.csv)", comment="#")
    need = {"id", "source", "artifact", "description"}
    if not need <= set(df.columns):
        raise RegistryError(f"{path}: needs the columns {sorted(need)}, has {sorted(df.columns)}; restore it from "
                            "the repository (git checkout data/artifacts.csv)")
    bad = [i for i in df["id"] if not _ID_RE.match(i)]
    if bad:
        raise RegistryError(f"{path}: malformed ids {bad[:5]}{' …' if len(bad) > 5 else ''} (expected "
                            "'<key>-table-<n>', '<key>-eq-<n>' …); correct them or restore the file (git checkout)")
    if df["id"].duplicated().any():
        raise RegistryError(f"{path}: duplicated ids {df['id'][df['id'].duplicated()].tolist()}")
    return df


def load_table(table_id: str) -> pd.DataFrame:
    """An exported comparison table with typed columns and its provenance.

    Numeric columns (``paper``, ``reproduced``, ``abs_error``, ``rel_error``, ``tolerance``) are
    floats (NaN where the cell holds text or nothing: the printed form is in ``paper_text``,
    ``reproduced_text``); ``df.attrs`` holds the sidecar (title, notebook, commit, seeds, package
    versions).  ``table_id`` as printed by ``python -m replication status``: a table id, or an
    artifact id covered by one table.  An artifact covered by several tables raises
    :class:`~replication.registry.schema.RegistryError` listing all of them (one call always returns one table);
    :func:`load_tables` returns them all.

    Parameters
    ----------
    table_id : str
        A table id, or an artifact id covered by one table.

    Returns
    -------
    pandas.DataFrame
        The table, numeric columns as floats (each in its row's ``unit``; ``rel_error`` and a
        relative tolerance dimensionless), ``attrs`` the sidecar.

    Raises
    ------
    RegistryError
        An unknown id; a CSV or sidecar that is missing or damaged; a CSV that is not the table its
        notebook computed (its digest differs from the sidecar's ``table_digest``: a cell edited by
        hand is refused, never read as NaN).
    """
    table_id = resolve_table_id(table_id)
    df = read_table(table_id)
    meta = _sidecar(table_id)
    changed = _digest_problem(table_id, meta)
    if changed:                         # a cell edited by hand would be read as NaN, or as another number
        raise RegistryError(f"{tables_dir() / f'{table_id}.csv'}: {changed}")
    for c in NUMERIC_COLUMNS:
        if c in df.columns:
            df[c] = pd.to_numeric(df[c].replace("", np.nan), errors="coerce")
    df.attrs.update(meta)
    return df


def load_tables(ident: str) -> dict[str, pd.DataFrame]:
    """Every exported table behind an id printed by ``python -m replication status``, as
    ``{table_id: DataFrame}`` typed as by :func:`load_table` (one entry for a table id or an
    artifact covered by one table, one per table for an artifact covered by several).

    Parameters
    ----------
    ident : str
        A table id or an artifact id.

    Returns
    -------
    dict of str to pandas.DataFrame
        The tables in the order of ``tables/status.csv``.
    """
    return {tid: load_table(tid) for tid in resolve_table_ids(ident)}


def artifact_tables(artifact: Mapping[str, Any]) -> list[str]:
    """The exported table ids that reproduce one artifact of ``data/artifacts.csv``.

    By default the table with the artifact's own id; the optional ``tables`` column lists
    other ids (space-separated) when a chapter covers the artifact with check tables.

    Parameters
    ----------
    artifact : mapping
        A row of :func:`load_artifacts` (``id`` and optional ``tables``).

    Returns
    -------
    list of str
        The table ids.
    """
    extra = str(artifact.get("tables", "") or "").split()
    for tid in extra:
        validate_id(tid)
    return extra or [artifact["id"]]


SIDECAR_KEYS = {
    "id": (str,), "title": (str,), "source": (str,), "notebook": (str,), "table_digest": (str,),
    "library_version": (str,), "git_commit": (str, type(None)), "status_counts": (dict,),
}
"""The keys every sidecar ``tables/<id>.json`` carries (written by
:func:`~replication.registry.exports.compare`) with their JSON types; ``git_commit`` is null when the
table was computed outside a git checkout."""

SIDECAR_OPTIONAL = {
    "description": (str,), "seeds": (dict,), "packages": (dict,), "summary": (str,), "main_reading": (str,),
    "main_reading_evidence": (str,), "readings": (list,), "ruled_out": (dict,), "groups": (dict,),
}
"""The keys a sidecar may carry, with the JSON types the readers rely on."""


def _sidecar(table_id: str) -> dict:
    """The sidecar ``tables/<id>.json`` of a table as a dict, checked by every reader: a sidecar that is
    missing, not a JSON object, or lacks a key of :data:`SIDECAR_KEYS` (or holds a key of
    :data:`SIDECAR_KEYS` or :data:`SIDECAR_OPTIONAL` of another type, or another table's id) raises
    :class:`~replication.registry.schema.RegistryError` naming the file."""
    path = tables_dir() / f"{table_id}.json"
    fix = "re-run the notebook that exports the table, or restore it from the repository (git checkout)"
    if not path.exists():
        raise RegistryError(f"{path} does not exist: tables/{table_id}.csv has no sidecar (its title, commit and "
                            f"digest); {fix}")
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise RegistryError(f"{path} is not valid JSON ({str(exc).splitlines()[0][:100]}): {fix}") from None
    if not isinstance(meta, dict):
        raise RegistryError(f"{path} holds a {type(meta).__name__}, not a table's sidecar (a JSON object): {fix}")
    missing = [k for k in SIDECAR_KEYS if k not in meta]
    if missing:
        raise RegistryError(f"{path} is not a table's sidecar: it lacks {', '.join(missing)}; {fix}")
    for key, kinds in {**SIDECAR_OPTIONAL, **SIDECAR_KEYS}.items():
        if key in meta and not isinstance(meta[key], kinds):
            want = " or ".join("null" if k is type(None) else {str: "a string", dict: "an object",
                                                                 list: "a list"}[k] for k in kinds)
            raise RegistryError(f"{path}: {key} is {json.dumps(meta[key])[:40]}, not {want}; {fix}")
    if meta["id"] != table_id or not meta["title"].strip():
        what = f"the id {meta['id']!r}" if meta["id"] != table_id else "an empty title"
        raise RegistryError(f"{path}: the sidecar of {table_id} holds {what}; {fix}")
    return meta


def _digest_problem(table_id: str, meta: Mapping[str, Any]) -> str:
    """Why ``tables/<id>.csv`` is not the table its notebook computed (its SHA-256 differs from the
    sidecar's ``table_digest``: the CSV was edited by hand), or ``""`` when it is.  The one digest
    check, run by the audit of ``python -m replication index`` and ``status``
    (:func:`~replication.registry.audit.audit_table`) and by :func:`load_table`."""
    digest = hashlib.sha256((tables_dir() / f"{table_id}.csv").read_bytes()).hexdigest()
    if meta.get("table_digest") == digest:
        return ""
    return ("the CSV differs from the table its notebook computed (its content does not match the sidecar's "
            "table_digest): re-run the notebook, or restore it (git checkout); never edit a table by hand")


def resolve_table_ids(ident: str) -> list[str]:
    """The exported tables behind ``ident``: ``[ident]`` for a table id, the tables of
    ``tables/status.csv`` that cover an artifact id otherwise (one or several).  Raises
    :class:`~replication.registry.schema.RegistryError` for an artifact no table covers yet, and for an unknown id (naming
    every exported table of that source).

    Parameters
    ----------
    ident : str
        A table id or an artifact id, as ``python -m replication status`` prints them.

    Returns
    -------
    list of str
        The exported table ids.
    """
    try:
        validate_id(ident)
    except RegistryError as exc:
        near = _near_ids(ident) if isinstance(ident, str) and tables_dir().is_dir() else []
        if near:
            raise RegistryError(f"malformed table id {ident!r}: did you mean {', '.join(near)}?") from None
        raise exc from None
    if (tables_dir() / f"{ident}.csv").exists():
        return [ident]
    status_path = tables_dir() / "status.csv"
    if status_path.exists():
        fix = "rebuild it with python -m replication index (in a clone), or restore it (git checkout)"
        st = _read_csv(status_path, fix)
        if not {"id", "status", "tables"} <= set(st.columns):
            raise RegistryError(f"{status_path}: needs the columns id, status, tables; {fix}")
        hit = st[st["id"] == ident]
        if len(hit):
            tables = hit.iloc[0]["tables"].split()
            if not tables:
                raise RegistryError(f"{ident!r} is {hit.iloc[0]['status']}: no table has been exported for it yet")
            return tables
    elif ident in _artifact_ids():
        raise RegistryError(f"{status_path} does not exist: it lists the tables covering the artifact {ident!r}; "
                            "rebuild it with python -m replication index (in a clone), or restore it "
                            "(git checkout -- tables/status.csv)")
    read_table(ident)                   # not a table either: raises, naming the tables of that source
    return [ident]


def resolve_table_id(ident: str) -> str:
    """The one exported table behind ``ident`` (:func:`resolve_table_ids`); an artifact covered
    by several tables raises :class:`~replication.registry.schema.RegistryError` listing every one of them.

    Parameters
    ----------
    ident : str
        A table id, or an artifact id covered by one table.

    Returns
    -------
    str
        The table id.
    """
    tables = resolve_table_ids(ident)
    if len(tables) > 1:
        raise RegistryError(f"{ident!r} is covered by {len(tables)} tables: {', '.join(tables)}; name one of "
                            f"them, or use replication.load_tables({ident!r}) for all")
    return tables[0]
