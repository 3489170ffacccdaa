"""The readings ledgers of a table and the entry points of the verdict rule (CONTRIBUTING.md,
"Readings and the main reading"); the rule itself runs in :mod:`replication.registry.audit`.
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping

from replication.registry.locations import tables_dir
from replication.registry.reading import _sidecar

READING_SEPARATOR = " | "
"""A readings ledger names each row ``<reading> | <quantity of the main table>``."""


def readings_ledgers(table_id: str, meta: Mapping[str, Any] | None = None) -> list[str]:
    """The readings ledgers of an exported table: those its sidecar names (``readings``), else
    ``<key>-check-<rest>-readings`` for ``<key>-<rest>`` when that table is exported.

    Parameters
    ----------
    table_id : str
        An exported table id.
    meta : mapping, optional
        Its sidecar, when already read.

    Returns
    -------
    list of str
        The ledgers' table ids (empty when it has none).
    """
    meta = _sidecar(table_id) if meta is None else meta
    if meta.get("readings"):
        return list(meta["readings"])
    key, rest = table_id.split("-", 1)
    cand = f"{key}-check-{rest}-readings"
    return [cand] if (tables_dir() / f"{cand}.csv").exists() else []


def verdict_violations(table_ids: Iterable[str] | None = None) -> list[str]:
    """Every problem of the stored tables, as messages naming table, row and reason
    (:func:`replication.registry.audit.audit`: the status criteria, the verdict rule of
    CONTRIBUTING.md, "Readings and the main reading", and the digests); empty when none.

    Parameters
    ----------
    table_ids : iterable of str, optional
        The tables to check; every exported table (and every stray CSV) by default.

    Returns
    -------
    list of str
        One message per problem.
    """
    from replication.registry import audit as _audit

    return [str(p) for p in _audit.audit(table_ids)]


def check_verdicts(table_ids: Iterable[str] | None = None) -> None:
    """Raise :class:`~replication.registry.schema.RegistryError` listing every problem of the stored tables (:func:`verdict_violations`).

    Parameters
    ----------
    table_ids : iterable of str, optional
        The tables to check; every exported table by default.

    Raises
    ------
    RegistryError
        Listing every problem.
    """
    from replication.registry import audit as _audit

    _audit.check(table_ids)
