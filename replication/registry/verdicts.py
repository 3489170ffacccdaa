"""How a row is judged, and the status that follows from its evidence (CONTRIBUTING.md, "Statuses").

A comparison row declares its *basis* — the kind of comparison it makes — and the evidence that
kind needs; its status is then a pure function of that evidence (:func:`derive_status`), never a
word a chapter types.  The bases:

``value``
    a number against a tolerance stated before the comparison;
``verdict``
    a verdict or pattern (observable or not, an ordering, a sign, a shape) against the print,
    with the readings ledger where the print leaves a choice open;
``parts``
    two printed parts against each other (an equation and a table, a header and its entries,
    the text and a table);
``derivation``
    a printed formula or value against a derivation from first principles;
``claim``
    a sentence of the print against the rows it rests on (``rests_on``);
``stand-in``
    a labelled simulation standing in for data or settings the print does not publish;
``unstated``
    the print lacks a quantity the check needs (the note names it).

The evidence: ``agrees`` (computed by the chapter's code: does the row's own comparison agree with
the print — a verdict equal to the printed one, a claim that holds in the print's own numbers, a
stand-in that does not contradict the print within what the unknowns allow, a printed formula equal
to the derived one, two printed parts that agree); for ``value`` rows the stored numbers and
tolerance decide it instead; the readings of the table's ledger that reach the print (and whether
each keeps the rest of its group, see :class:`LedgerEvidence`); for ``claim`` rows the statuses of
the rows named in ``rests_on``.

This module knows no files: :mod:`replication.registry.audit` reads the stored tables and calls it.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any, Iterable

BASES = {
    "value": "a number against a tolerance stated before the comparison",
    "verdict": "a verdict or pattern against the print (with the readings ledger where the print leaves a choice)",
    "parts": "two printed parts against each other",
    "derivation": "a printed formula or value against a derivation from first principles",
    "claim": "a sentence of the print against the rows it rests on",
    "stand-in": "a labelled simulation standing in for data the print does not publish",
    "unstated": "the print lacks a quantity the check needs",
}
"""The comparison kinds a row may declare (the ``basis`` column), each with what it compares."""

AGREES = ("yes", "no")
"""The stored values of the ``agrees`` column (empty for ``value`` rows, whose numbers decide)."""

REACHING = ("reproduced", "qualitative", "analog")
"""Statuses with which a row reaches the print: within tolerance, found to hold, not contradicting it."""

FAILING = ("not-reproduced",)
"""The status of a comparison that misses the print under every faithful reading."""


@dataclass(frozen=True)
class LedgerEvidence:
    """What a table's readings ledger says about one failing row.

    Attributes
    ----------
    reaching : tuple of str
        The readings (not ruled out by printed evidence) under which the row reaches the print.
    keeping_group : tuple of str
        Those of ``reaching`` that also reach every other row of the row's group (e.g. the same
        column of a printed table) that the main reading reaches: a reading that reaches this row
        only by losing another printed value of its group does not reconcile the print.
    grouped : bool
        Whether the table declares groups (otherwise every reaching reading counts as keeping).
    """

    reaching: tuple[str, ...] = ()
    keeping_group: tuple[str, ...] = ()
    grouped: bool = False


@dataclass(frozen=True)
class Evidence:
    """The evidence of one row, as stored (read from the stored tables by :mod:`replication.registry.audit`).

    Attributes
    ----------
    basis : str
        One of :data:`BASES`.
    agrees : bool or None
        The chapter's computed agreement (``None`` for ``value`` rows: the numbers decide).
    within : bool or None
        For a row with numbers and a tolerance: whether the stored error lies within it.
    ledger : LedgerEvidence or None
        For a failing row of a table with a readings ledger.
    rests_on : tuple of str
        For a ``claim``: the statuses of the rows it rests on.
    has_test : bool
        Whether the evidence column names a notebook and a test that exist (needed by an erratum).
    """

    basis: str
    agrees: bool | None = None
    within: bool | None = None
    ledger: LedgerEvidence | None = None
    rests_on: tuple[str, ...] = field(default_factory=tuple)
    has_test: bool = False


def after_ledger(ledger: LedgerEvidence | None, failing: str) -> str:
    """A comparison that misses the print under the main reading, judged against the ledger:
    ``failing`` when no reading reaches the print; ``unverifiable`` when a reading the print leaves
    open reaches it and keeps the rest of its group (an unstated choice, chosen to suit, reaches the
    print); ``inconsistent`` when every reading that reaches it loses another printed value of the
    same group (the printed group contradicts itself), or when the row was an erratum (a printed
    value that a faithful reading reproduces is another convention, not a misprint).

    Parameters
    ----------
    ledger : LedgerEvidence or None
        What the table's ledger says about the row.
    failing : str
        ``"not-reproduced"`` or ``"erratum"``: the status without a reaching reading.

    Returns
    -------
    str
        The status.
    """
    if ledger is None or not ledger.reaching:
        return failing
    if ledger.grouped and not ledger.keeping_group:
        return "inconsistent"
    return "unverifiable" if failing == "not-reproduced" else "inconsistent"


def derive_status(ev: Evidence) -> str:
    """The status of a row from its declared basis and evidence (CONTRIBUTING.md, "Statuses").

    ``value``: within the tolerance → ``reproduced``; outside → the ledger step.
    ``verdict``: agrees → ``qualitative``; otherwise → the ledger step.
    The ledger step: no reading reaches the print → ``not-reproduced``; a reading that reaches it
    and keeps its group → ``unverifiable``; only readings that lose another printed value of the
    group → ``inconsistent``.
    ``parts``: agree → ``reproduced`` when compared against a tolerance, else ``qualitative``;
    disagree → ``inconsistent``.
    ``derivation``: agrees (or within tolerance) → ``reproduced`` with a tolerance, else
    ``qualitative``; disagrees → ``erratum`` (needs a test; a reading of the ledger reaching the
    print makes it ``inconsistent``: another convention, not a misprint).
    ``claim``: the claim fails on the print's own numbers → ``inconsistent``; else the worst of the
    rows it rests on: any ``not-reproduced`` → ``not-reproduced``; any ``unverifiable`` or
    ``pending`` → ``unverifiable``; any ``analog`` → ``analog``; otherwise ``qualitative``.
    ``stand-in``: does not contradict the print → ``analog``; contradicts it → ``not-reproduced``.
    ``unstated``: ``unverifiable``.

    Parameters
    ----------
    ev : Evidence
        The row's basis and evidence.

    Returns
    -------
    str
        The derived status.

    Raises
    ------
    ValueError
        An unknown basis, or evidence the basis needs that is missing (the message says which).
    """
    b = ev.basis
    if b not in BASES:
        raise ValueError(f"unknown basis {b!r}; one of {', '.join(BASES)}")
    if b == "value":
        if ev.within is None:
            raise ValueError("a 'value' row needs numbers and a tolerance")
        return "reproduced" if ev.within else after_ledger(ev.ledger, "not-reproduced")
    if b == "unstated":
        return "unverifiable"
    if b == "claim":
        if not ev.rests_on:
            raise ValueError("a 'claim' row needs rests_on: the rows the claim rests on")
        if ev.agrees is None:
            raise ValueError("a 'claim' row needs agrees: whether the claim holds in the print's own numbers")
        if not ev.agrees:
            return "inconsistent"
        s = set(ev.rests_on)
        if "not-reproduced" in s:
            return "not-reproduced"
        if s & {"unverifiable", "pending"}:
            return "unverifiable"
        if "analog" in s:
            return "analog"
        return "qualitative"
    ok = ev.within if ev.within is not None else ev.agrees
    if ok is None:
        raise ValueError(f"a {b!r} row needs agrees (or numbers and a tolerance)")
    if b == "verdict":
        return "qualitative" if ok and ev.within is None else "reproduced" if ok else \
            after_ledger(ev.ledger, "not-reproduced")
    if b == "parts":
        return ("reproduced" if ev.within is not None else "qualitative") if ok else "inconsistent"
    if b == "derivation":
        if ok:
            return "reproduced" if ev.within is not None else "qualitative"
        if ev.ledger is not None and ev.ledger.reaching:
            return "inconsistent"
        return "erratum"
    # stand-in
    return "analog" if ok else "not-reproduced"


def parse_agrees(text: Any) -> bool | None:
    """The stored ``agrees`` cell as a boolean (``None`` when empty).

    Parameters
    ----------
    text : str or bool or None
        ``"yes"``, ``"no"``, a boolean, or empty.

    Returns
    -------
    bool or None

    Raises
    ------
    ValueError
        Any other value.
    """
    if text is None or (isinstance(text, float) and math.isnan(text)) or text == "":
        return None
    if isinstance(text, bool) or (type(text).__module__ == "numpy" and type(text).__name__ in ("bool", "bool_")):
        return bool(text)
    if text in AGREES:
        return text == "yes"
    raise ValueError(f"agrees must be 'yes', 'no' or empty, not {text!r}")


def format_agrees(value: Any) -> str:
    """The ``agrees`` cell to store: ``"yes"``, ``"no"`` or ``""``.

    Parameters
    ----------
    value : bool, str or None

    Returns
    -------
    str
    """
    v = parse_agrees(value)
    return "" if v is None else "yes" if v else "no"


def split_refs(text: str) -> list[str]:
    """The row references of a ``rests_on`` cell: ``<table id>#<quantity>`` or a table id, separated by ``; ``
    (a ``;`` inside a quantity stays: a reference starts with a table id).

    Parameters
    ----------
    text : str

    Returns
    -------
    list of str
    """
    parts = re.split(r";\s*(?=[a-z][a-z0-9]*-[a-z0-9])", str(text or ""))   # a quantity may itself hold "; "
    return [t.strip() for t in parts if t.strip()]


def worst(statuses: Iterable[str]) -> str:
    """The worst of row statuses for a roll-up that must not hide a failure (not-reproduced first).

    Parameters
    ----------
    statuses : iterable of str

    Returns
    -------
    str
    """
    order = ("not-reproduced", "unverifiable", "pending", "analog", "inconsistent", "erratum", "qualitative",
             "reproduced")
    present = set(statuses)
    return next((s for s in order if s in present), "pending")

