"""A caption against the text that introduces its table: the same qualifier, or two printed parts
that disagree.

A qualifier is what a caption says about the conditions of its table ("before" or "after
temperature compensation", "with" or "without roll").  The comparison reads it from both printed
parts with one pattern (a regular expression whose first group is the qualifier), maps synonyms
to one word (``有`` and ``带``, "with", are the same), and compares the two sets: equal sets
agree; anything else is two printed parts that disagree (basis ``parts``, so ``inconsistent``).
A part in which the pattern finds nothing cannot be compared and is refused.
"""

from __future__ import annotations

import re
from typing import Any, Mapping, Sequence

import pandas as pd

__all__ = ["qualifiers", "qualifier_rows"]


def qualifiers(text: str, pattern: str, synonyms: Mapping[str, str] | None = None) -> frozenset[str]:
    """The qualifiers ``pattern`` finds in ``text`` (its first group), synonyms mapped to one word.

    Parameters
    ----------
    text : str
        A printed caption, heading or header.
    pattern : str
        A regular expression with one group, the qualifier (e.g. ``"温度补偿([前后])"``).
    synonyms : mapping of str to str, optional
        Qualifiers that mean the same, mapped to the one word used (e.g. ``{"带": "有"}``).

    Returns
    -------
    frozenset of str
        The qualifiers found (empty when none).

    Raises
    ------
    ValueError
        When the pattern has no group.
    """
    rx = re.compile(pattern)
    if rx.groups < 1:
        raise ValueError(f"pattern {pattern!r} needs a group: the qualifier it reads")
    syn = dict(synonyms or {})
    return frozenset(syn.get(m, m) for m in rx.findall(str(text)))


def qualifier_rows(printed: pd.DataFrame, checks: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """Comparison rows (``basis="parts"``), one per check: a caption's qualifier against another part's.

    Parameters
    ----------
    printed : pandas.DataFrame
        The transcription: ``quantity``, ``value`` (the text as printed) and ``line``.
    checks : sequence of mappings
        Each with ``caption`` and ``against`` (quantities of ``printed``), ``pattern`` and optionally
        ``synonyms`` (see :func:`qualifiers`) and ``meaning`` (the qualifier's words in English, for
        the note, e.g. ``{"前": "before", "后": "after"}``).

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`, named
        ``"<caption> against <part>"``.

    Raises
    ------
    ValueError
        When a part is not in the transcription, or the pattern finds no qualifier in one of them.
    """
    by_q = printed.set_index("quantity")
    rows = []
    for c in checks:
        parts = []
        for key in ("caption", "against"):
            q = c[key]
            if q not in by_q.index:
                raise ValueError(f"{q!r} is not in the transcription; it has {list(by_q.index)[:8]} ...")
            found = qualifiers(by_q.loc[q, "value"], c["pattern"], c.get("synonyms"))
            if not found:
                raise ValueError(f"the pattern {c['pattern']!r} finds no qualifier in {q!r}: "
                                 f"{by_q.loc[q, 'value']!r}")
            parts.append((q, found, by_q.loc[q, "line"]))
        (qa, fa, la), (qb, fb, lb) = parts
        words = dict(c.get("meaning", {}))
        say = lambda s: " and ".join(words.get(w, w) for w in sorted(s))  # noqa: E731
        rows.append(dict(quantity=f"{qa} against {qb}", unit="", paper=f"{say(fa)} (line {la})",
                         reproduced=f"{say(fb)} (line {lb})", basis="parts", agrees=fa == fb,
                         note=(f"the {qa.split(' ', 2)[-1]} says {say(fa)}, the {qb.split(' ', 2)[-1]} says {say(fb)}"
                               + ("" if fa == fb else ": two printed parts disagree"))))
    return rows
