"""Links from the generated status pages into the book: an artifact's chapter, and the tables a
chapter shows (its labelled targets).
"""

from __future__ import annotations

import re
from pathlib import Path


def _chapter_link(row) -> str:
    nb = str(row.get("notebook", "")).split()
    if not nb or not nb[0].startswith("book/"):
        return f"`{row['id']}`"
    return f"{{doc}}`{row['id']} </{nb[0][len('book/'):].removesuffix('.ipynb')}>`"


def _notebook_targets(root: Path, notebook: str) -> set[str]:
    """The table ids a stored notebook displays with a target (see :func:`~replication.registry.markdown.display_table`)."""
    path = root / notebook
    if not notebook or not path.exists():
        return set()
    return set(re.findall(r"\(([a-z0-9][a-z0-9-]*)\)=", path.read_text(encoding="utf-8")))


def _table_links(row, root: Path, up: str) -> str:
    """Each table of an artifact: a link to where the chapter shows it (when it does) and its CSV."""
    nb = str(row.get("notebook", "")).split()
    shown = set().union(*(_notebook_targets(root, n) for n in nb)) if nb else set()
    out = []
    for tid in str(row.get("tables", "")).split():
        ref = f"{{ref}}`shown <{tid}>`" if tid in shown else ""
        out.append(f"{{download}}`{tid}.csv <{up}tables/{tid}.csv>`" + (f" ({ref})" if ref else ""))
    return "<br>".join(out) or "-"
