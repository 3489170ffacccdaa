"""The status of an artifact from the statuses of its rows, the tallies of artifacts by status, the
artifacts that hold not-reproduced rows, and the status bar that draws a tally.
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping

import pandas as pd

from replication.registry.reading import _sidecar, read_table
from replication.registry.schema import STATUSES, RegistryError

ARTIFACT_STATUSES = ("reproduced", "qualitative", "mixed", "analog", "unverifiable", "not-reproduced",
                     "erratum", "inconsistent", "pending")
"""Statuses of a whole artifact (``tables/status.csv``): the row statuses plus ``mixed``."""


def summarize_status(statuses: Iterable[str]) -> str:
    """The reproduction status of an artifact from its rows (CONTRIBUTING.md, "Statuses").

    Errata and inconsistencies are findings about the print, counted beside the status, never
    deciding it.  Of the other rows: all ``pending`` → ``pending``; all ``reproduced`` or
    ``qualitative`` → ``reproduced`` (``qualitative`` if none is numeric); all of one other kind
    (``analog``, ``unverifiable``, ``not-reproduced``) → that kind; any other combination →
    ``mixed``, whose split the row counts show.  An artifact with only errata (or only
    inconsistencies) rows is ``erratum`` (``inconsistent``); with no rows, ``pending``.

    Parameters
    ----------
    statuses : iterable of str
        The row statuses (each of :data:`~replication.registry.schema.STATUSES`).

    Returns
    -------
    str
        One of :data:`ARTIFACT_STATUSES`.
    """
    present = list(statuses)
    for s in present:
        if s not in STATUSES:
            raise RegistryError(f"unknown status {s!r}")
    rest = {s for s in present if s not in ("erratum", "inconsistent")}
    if not rest:
        return "erratum" if "erratum" in present else "inconsistent" if "inconsistent" in present else "pending"
    if rest == {"pending"}:
        return "pending"
    if rest <= {"reproduced", "qualitative"}:
        return "reproduced" if "reproduced" in rest else "qualitative"
    if len(rest) == 1:
        return rest.pop()
    return "mixed"


def status_label(row: Mapping[str, Any]) -> str:
    """``status`` of a ``tables/status.csv`` row with its findings about the print, e.g.
    ``reproduced, 52 errata`` — so that an artifact's status never hides its errata; ``mixed``
    always carries its split, failures first: ``mixed (3 not-reproduced, 20 reproduced)``.

    Parameters
    ----------
    row : mapping
        A row of ``tables/status.csv`` (``status`` and the row counts per status).

    Returns
    -------
    str
        The label shown on the status page.
    """
    n_e, n_i = int(row.get("erratum", 0) or 0), int(row.get("inconsistent", 0) or 0)
    extra = ([f"{n_e} {'erratum' if n_e == 1 else 'errata'}"] if n_e else []) + \
            ([f"{n_i} {'inconsistency' if n_i == 1 else 'inconsistencies'}"] if n_i else [])
    head = str(row["status"])
    if head == "mixed":          # a mixed artifact always carries its split (failures first)
        order = ("not-reproduced", "unverifiable", "analog", "reproduced", "qualitative", "pending")
        head += " (" + ", ".join(f"{int(row.get(s.replace('-', '_'), 0) or 0)} {s}" for s in order
                                 if int(row.get(s.replace("-", "_"), 0) or 0)) + ")"
    return ", ".join([head] + extra)


def _first_clause(text: str, n: int = 160) -> str:
    """The first sentence or clause of a note, whole (never cut inside a word or a number)."""
    t = " ".join(str(text).split())
    for sep in (". ", "; ", ": "):
        head = t.split(sep, 1)[0]
        if len(head) <= n:
            return head.rstrip(".")
    return t[:n].rsplit(" ", 1)[0]


def failing_artifacts(status: pd.DataFrame) -> pd.DataFrame:
    """The paper artifacts holding ``not-reproduced`` rows, most such rows first, each with its
    one-line reason: the ``summary`` of its table's sidecar, else the first clause of the first
    not-reproduced row's note.  Columns ``id``, ``source``, ``artifact``, ``label``,
    ``not_reproduced``, ``tables``, ``notebook``, ``reason``.

    Parameters
    ----------
    status : pandas.DataFrame
        ``tables/status.csv`` as text (:func:`~replication.registry.index.build_index`).

    Returns
    -------
    pandas.DataFrame
        One row per failing artifact, most not-reproduced rows first.
    """
    sub = status[(status["kind"] == "paper") & (status["not_reproduced"].astype(int) > 0)]
    rows = []
    for _, r in sub.iterrows():
        reason = ""
        for tid in str(r["tables"]).split():
            meta = _sidecar(tid)
            df = read_table(tid)
            if not (df["status"] == "not-reproduced").any():
                continue
            notes = [n for n in df.loc[df["status"] == "not-reproduced", "note"] if str(n).strip()]
            reason = meta.get("summary") or (_first_clause(notes[0]) if notes else
                                             "differs from the print beyond the tolerance stated before comparing")
            break
        rows.append({"id": r["id"], "source": r["source"], "artifact": r["artifact"], "label": status_label(r),
                     "not_reproduced": int(r["not_reproduced"]), "tables": r["tables"], "notebook": r["notebook"],
                     "reason": reason})
    out = pd.DataFrame(rows, columns=["id", "source", "artifact", "label", "not_reproduced", "tables", "notebook",
                                      "reason"])
    return out.sort_values("not_reproduced", ascending=False, kind="stable").reset_index(drop=True)


def status_tally(status: pd.DataFrame) -> dict[str, str]:
    """One line per kind of artifact (``paper``, ``supplementary``): how many have each status
    and how many errata they carry — paper artifacts are never counted with the package's own
    checks.

    Parameters
    ----------
    status : pandas.DataFrame
        ``tables/status.csv`` as text.

    Returns
    -------
    dict of str to str
        ``{kind: line}``.
    """
    out = {}
    for kind in ("paper", "supplementary"):
        part = status[status["kind"] == kind]
        tally = part["status"].value_counts()
        head = ", ".join(f"{int(tally[s])} {s}" for s in ARTIFACT_STATUSES if int(tally.get(s, 0)))
        n_e, n_i = int(part["erratum"].sum()), int(part["inconsistent"].sum())
        out[kind] = (f"{len(part)} {kind} artifacts: {head}; {n_e} {'erratum' if n_e == 1 else 'errata'} and "
                     f"{n_i} {'inconsistency' if n_i == 1 else 'inconsistencies'} recorded in their rows")
    return out


STATUS_COLOURS = {"reproduced": "#2e7d32", "qualitative": "#81c784", "mixed": "#f9a825", "analog": "#90a4ae",
                  "unverifiable": "#bdbdbd", "not-reproduced": "#c62828", "pending": "#eeeeee"}
"""Colour of each artifact status in the status bars of the book (colour-blind safe order:
green shades for reproduced, amber for mixed, grey for analog, red for not reproduced)."""


def status_bar_html(counts: Mapping[str, int]) -> str:
    """A horizontal bar of artifact statuses (inline HTML, one segment per status, width ∝ count,
    the count written in it and the status in its tooltip) followed by its legend.

    Parameters
    ----------
    counts : mapping of str to int
        Artifacts per status.

    Returns
    -------
    str
        The inline HTML of the bar.
    """
    total = sum(int(v) for v in counts.values())
    if total <= 0:
        raise RegistryError("status_bar_html: no artifact to draw")
    segs, legend = [], []
    for st in ARTIFACT_STATUSES:
        n = int(counts.get(st, 0))
        if st not in STATUS_COLOURS or n == 0:
            continue
        w = 100.0 * n / total
        segs.append(f'<span class="status-seg" style="width:{w:.2f}%;background:{STATUS_COLOURS[st]}" '
                    f'title="{n} {st}">{n}</span>')
        legend.append(f'<span class="status-key" style="background:{STATUS_COLOURS[st]}"></span>{st} {n}')
    return (f'<div class="status-bar">{"".join(segs)}</div>'
            f'<div class="status-legend">{" &nbsp; ".join(legend)}</div>')
