"""Where the registry reads and writes: the clone (or the data packaged with an installed wheel),
``data/``, ``data/paper/`` and ``tables/``; the form of a table id.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path

from replication.registry.schema import _ID_RE, SOURCE_KEYS, RegistryError

PACKAGED_DATA = Path(__file__).resolve().parents[1] / "_data"
"""Where an installed (non-editable) wheel keeps the files the read side needs, laid out as in a
clone: ``tables/``, ``data/artifacts.csv``, ``data/sources.bib`` and ``data/paper/`` (copied there
when the wheel is built: ``setup.py``).  Absent in a clone and in an editable install."""


def _is_clone(path: Path) -> bool:
    """Whether ``path`` is the root of a clone of the repository (its ``pyproject.toml``, the
    package's sources and ``data/artifacts.csv``)."""
    return ((path / "pyproject.toml").is_file() and (path / "replication" / "__init__.py").is_file()
            and (path / "data" / "artifacts.csv").is_file())


def _clone_root() -> Path | None:
    """The clone the registry works in, by the first rule that applies: ``$REPLICATION_ROOT``; the
    clone the package is imported from (an editable install, or ``PYTHONPATH`` at a clone); a
    clone containing the current directory.  ``None`` outside any clone."""
    env = os.environ.get("REPLICATION_ROOT")
    if env:
        return _resolved(env)
    here = Path(__file__).resolve().parents[2]
    if _is_clone(here):
        return here
    cwd = Path.cwd().resolve()
    return next((p for p in (cwd, *cwd.parents) if _is_clone(p)), None)


@functools.lru_cache(maxsize=64)
def _resolved(path: str) -> Path:
    """``Path(path).resolve()``, once per value of ``$REPLICATION_ROOT`` (every read of a table asks)."""
    return Path(path).resolve()


def project_root() -> Path:
    """The root of the clone, where chapters write their tables: ``$REPLICATION_ROOT``, else the
    clone the package is imported from, else a clone containing the current directory.

    Only a clone is written to (:func:`~replication.registry.exports.compare`, ``python -m replication index``); reading works
    from an installed package too (:func:`data_root`).

    Returns
    -------
    pathlib.Path
        The absolute path of the repository root.

    Raises
    ------
    RegistryError
        Outside a clone: the message says what reads still work.
    """
    root = _clone_root()
    if root is None:
        where = f" (this installed package reads the tables it ships, {PACKAGED_DATA})" if PACKAGED_DATA.is_dir() else ""
        raise RegistryError("not in a clone of the repository: tables are written only in a clone; run inside it "
                            f"or set REPLICATION_ROOT to it{where}")
    return root


def data_root() -> Path:
    """Where the tables, the register and the artifact list are read from, by the first rule that
    applies: ``$REPLICATION_ROOT``; the clone the package is imported from (an editable install
    reads the clone's live tables); a clone containing the current directory; the data shipped
    inside the installed package (:data:`PACKAGED_DATA`).

    Returns
    -------
    pathlib.Path
        A folder holding ``tables/`` and ``data/``.

    Raises
    ------
    RegistryError
        Neither a clone nor an installed package with its data.
    """
    root = _clone_root()
    env = os.environ.get("REPLICATION_ROOT")
    if env and root is not None and not root.is_dir():
        raise RegistryError(f"REPLICATION_ROOT={env} is not a directory: set it to the root of a clone of the "
                            "repository (the folder holding tables/ and data/), or unset it")
    if root is not None:
        return root
    if PACKAGED_DATA.is_dir():
        return PACKAGED_DATA
    raise RegistryError("cannot find the tables: not in a clone of the repository, and this installation of "
                        "replication carries no data; run inside the clone, set REPLICATION_ROOT to it, or "
                        "install the package from a clone (pip install <clone>)")


def paper_dir() -> Path:
    """The folder of the paper values, ``data/paper/`` under :func:`data_root`.

    Returns
    -------
    pathlib.Path
        ``<root>/data/paper``.
    """
    return data_root() / "data" / "paper"


def tables_dir() -> Path:
    """The folder of the exported tables, ``tables/`` under :func:`data_root` (a clone's, or
    the copy an installed package ships).

    Returns
    -------
    pathlib.Path
        ``<root>/tables``.
    """
    return data_root() / "tables"


def validate_id(table_id: str) -> str:
    """Check a table id against ``<key>-(table|figure|eq|claim|check|print)-<n>`` (``print``: an item
    of the document as a whole, e.g. its reference list).

    Parameters
    ----------
    table_id : str
        A table id such as ``'chen2019-table-2-3'``.

    Returns
    -------
    str
        ``table_id`` unchanged.

    Raises
    ------
    RegistryError
        A malformed id, with the accepted forms.
    """
    if not isinstance(table_id, str) or not _ID_RE.match(table_id):
        raise RegistryError(
            f"malformed table id {table_id!r}: expected '<key>-table-<n>', '<key>-figure-<n>', "
            f"'<key>-eq-<n>', '<key>-claim-<name>', '<key>-print-<name>' or '<key>-check-<name>' with key one of "
            f"{', '.join(SOURCE_KEYS)} (lower case, e.g. 'chen2019-table-2-3')"
        )
    return table_id


def _write_if_changed(path: Path, content: str) -> None:
    project_root()                      # only a clone is written to: refuses outside one
    if not path.exists() or path.read_text(encoding="utf-8") != content:
        path.write_text(content, encoding="utf-8")
