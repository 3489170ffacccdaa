"""The read side of the registry: a stored table and its sidecar, the list of exported tables, the
artifact list ``data/artifacts.csv``, the resolution of an id (a table, a multi-table artifact)
with near-miss suggestions, and the typed loaders :func:`load_table` and :func:`load_tables`.
"""

from __future__ import annotations

import difflib
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


def _read_csv(path: Path, fix: str, **kw) -> pd.DataFrame:
    """``path`` read as text columns; a file that is empty, not CSV or not UTF-8 raises :class:`~replication.registry.schema.RegistryError`
    naming it and ``fix``."""
    try:
        return pd.read_csv(path, dtype=str, keep_default_na=False, encoding="utf-8", **kw)
    except pd.errors.EmptyDataError:
        why = "is empty"
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        why = f"is not a readable UTF-8 CSV file ({str(exc).splitlines()[0][:120]})"
    except OSError as exc:
        why = f"cannot be read ({exc.strerror or exc})"
    raise RegistryError(f"{path} {why}: {fix}")


def _known_ids() -> list[str]:
    """Every id the read side answers to: the exported tables and the artifacts of ``data/artifacts.csv``."""
    ids = set(list_tables())
    try:
        ids.update(load_artifacts()["id"])
    except RegistryError:
        pass
    return sorted(ids)


def _near_ids(ident: str) -> list[str]:
    """The known ids nearest to ``ident`` (at most five, by ``difflib``; case and spaces ignored)."""
    known = _known_ids()
    return (difflib.get_close_matches(ident, known, n=5, cutoff=0.6)
            or difflib.get_close_matches(ident.strip().lower(), known, n=5, cutoff=0.6))


def _unknown_id(ident: str) -> str:
    """The message for an id that names no table: the nearest known ids (at most five), or where to find them."""
    d = tables_dir()
    if not d.is_dir():
        env = os.environ.get("REPLICATION_ROOT")
        where = f" (REPLICATION_ROOT={env})" if env else ""
        return (f"no exported table {ident!r}: {d} does not exist{where}; run inside a clone of the repository or "
                "set REPLICATION_ROOT to its root")
    near = _near_ids(ident)
    hint = f"did you mean {', '.join(near)}?" if near else "no known id is close to it;"
    return f"no exported table {ident!r}: {hint} (python -m replication status lists every id)"


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
    """
    table_id = resolve_table_id(table_id)
    df = read_table(table_id)
    for c in NUMERIC_COLUMNS:
        if c in df.columns:
            df[c] = pd.to_numeric(df[c].replace("", np.nan), errors="coerce")
    df.attrs.update(_sidecar(table_id))
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


def _sidecar(table_id: str) -> dict:
    """The sidecar ``tables/<id>.json`` of a table as a dict (empty when there is none); a sidecar that is
    not a JSON object raises :class:`~replication.registry.schema.RegistryError` naming the file."""
    path = tables_dir() / f"{table_id}.json"
    if not path.exists():
        return {}
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise RegistryError(f"{path} is not valid JSON ({str(exc).splitlines()[0][:100]}): re-run the notebook that "
                            "exports the table, or restore it from the repository (git checkout)") from None
    if not isinstance(meta, dict):
        raise RegistryError(f"{path} holds a {type(meta).__name__}, not a table's sidecar (a JSON object): re-run "
                            "the notebook that exports the table, or restore it from the repository (git checkout)")
    return meta


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
