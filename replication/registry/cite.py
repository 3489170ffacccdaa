"""Citation: BibTeX for a table, for every table of an artifact, and for a source document.
"""

from __future__ import annotations

import re

from replication._meta import repository_url
from replication.registry.locations import data_root
from replication.registry.reading import load_table, resolve_table_ids
from replication.registry.schema import SOURCE_KEYS, STATUSES, RegistryError
from replication.registry.tallies import summarize_status

PACKAGE_YEAR = 2026
"""Year of the package release cited by :func:`bibtex_for` (as in CITATION.cff)."""


def bibtex_for(ident: str) -> str:
    """BibTeX citing the exported table ``ident``, or every table covering the artifact ``ident``.

    One ``@misc`` entry per table: year and version of the package, its repository (``url``),
    the commit recorded in the table's sidecar (the one on top of which its values were
    computed, not the checkout's), its status with the row split; a table reproducing a paper
    relates to that paper's entry, which follows once; a supplementary check of the package's
    own cites the package only.

    Parameters
    ----------
    ident : str
        A table id or an artifact id.

    Returns
    -------
    str
        The entries, one per table, then each reproduced source's entry once.
    """
    entries, sources = [], []
    for table_id in resolve_table_ids(ident):
        entry, source = _table_bibtex(table_id)
        entries.append(entry)
        if source in SOURCE_KEYS and source not in sources:
            sources.append(source)
    return "\n".join(entries) + "".join("\n" + source_bibtex(s) for s in sources)


def _table_bibtex(table_id: str) -> tuple[str, str]:
    """The ``@misc`` entry of one exported table, and the source key it reproduces."""
    df = load_table(table_id)           # the sidecar checked, and the CSV the one its notebook computed
    meta = df.attrs
    source = meta["source"]
    commit = meta["git_commit"] or "unknown"        # null: computed outside a git checkout
    version = meta["library_version"]
    counts = df["status"].value_counts()
    split = ", ".join(f"{int(counts[s])} {s}" for s in STATUSES if int(counts.get(s, 0)))
    overall = summarize_status(df["status"])
    is_paper = source in SOURCE_KEYS
    title = meta["title"]
    lines = [f"@misc{{repro-{table_id},",
             f"  title        = {{{{{title}}}}},",
             "  author       = {{SINS/GNSS reproduction package contributors}},",
             f"  year         = {{{PACKAGE_YEAR}}},",
             f"  version      = {{{version}}},",
             f"  howpublished = {{Table \\texttt{{tables/{table_id}.csv}} of the reproduction package "
             f"\\texttt{{replication}} v{version}, commit {commit[:12]}}},",
             f"  url          = {{{repository_url()}}},",
             f"  note         = {{Status {overall} ({split}).{' Reproduces ' + source + '; cite the original as well.' if is_paper else ' A supplementary check of the package.'}}},"]
    if is_paper:
        lines.append(f"  related      = {{{source}}},")
    lines.append("}")
    return "\n".join(lines) + "\n", source


def source_bibtex(key: str) -> str:
    """The BibTeX entry of one of the four source documents (from ``data/sources.bib``).

    Parameters
    ----------
    key : str
        A source key (:data:`~replication.registry.schema.SOURCE_KEYS`).

    Returns
    -------
    str
        The entry with a trailing newline.

    Raises
    ------
    RegistryError
        ``data/sources.bib`` missing, not UTF-8, or without the entry (a citation of a reproduction
        that asks to cite the original as well must carry it).
    """
    path = data_root() / "data" / "sources.bib"
    fix = "restore it: git checkout -- data/sources.bib"
    if not path.is_file():
        raise RegistryError(f"{path} does not exist (it holds the entries of the source documents): {fix}")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise RegistryError(f"{path} is not UTF-8 ({exc.reason} at byte {exc.start}): {fix}") from None
    m = re.search(r"@\w+\{" + re.escape(key) + r",", text)
    if not m:
        raise RegistryError(f"{path} has no entry {key}: {fix}")
    depth, i = 0, m.start()
    for j in range(text.index("{", m.start()), len(text)):
        depth += {"{": 1, "}": -1}.get(text[j], 0)
        if depth == 0:
            return text[i : j + 1] + "\n"
    raise RegistryError(f"{path}: unbalanced braces in entry {key}")
