"""The methods of the four source documents, one sub-package per paper, built on
:mod:`replication.nav` and never on each other (the chapters' figures in :mod:`.plots`).

Two helpers are shared by the papers' comparison rows: :func:`readable`, a formula transcribed in
LaTeX (``data/paper/``) written in plain characters for a table cell, and :func:`transcription`,
the printed text and seed lines of a print-parts transcription by quantity.
"""

from __future__ import annotations

import re

_GREEK = {"varepsilon": "ε", "varphi": "φ", "phi": "φ", "psi": "ψ", "Omega": "Ω", "omega": "ω", "sigma": "σ",
          "pi": "π", "lambda": "λ", "delta": "δ", "cdot": "·", "approx": "≈", "times": "×", "circ": "°",
          "sim": "~", "dots": "…", "ldots": "…", "gg": "≫", "mp": "∓", "pm": "±"}
"""LaTeX commands :func:`readable` writes as their characters."""


def readable(latex: str) -> str:
    """A printed formula transcribed in LaTeX, written in plain characters for a table cell.

    Font commands (``\\mathbf``, ``\\boldsymbol``, ``\\text``, ...) keep their argument, ``\\frac{a}{b}``
    becomes ``a/b`` (each side parenthesized unless it is one token), ``\\sqrt{a}`` becomes ``√(a)``,
    ``^{-1}`` and ``^\\circ`` become ``⁻¹`` and ``°``, Greek letters and a few operators their characters;
    math delimiters, ``\\left``/``\\right``, spacing commands and ``\\tag``/``\\quad (n)`` numbers go.
    The words stay as printed; only the markup changes.

    Parameters
    ----------
    latex : str
        Text with inline or display LaTeX.

    Returns
    -------
    str
        The same text without LaTeX markup.
    """
    s = str(latex).replace("$$", "").replace("$", "")
    s = re.sub(r"\\(?:tag\{[^}]*\}|quad\s*\(\d+\))", "", s)
    s = re.sub(r"\\(?:left|right)\s*", "", s)
    s = re.sub(r"\\begin\{[bp]?matrix\}(.*?)\\end\{[bp]?matrix\}",
               lambda m: "[" + m.group(1).replace("&", ",").replace("\\\\", ";") + "]", s, flags=re.S)
    s = re.sub(r"\\(?:quad|qquad|,|;|!)|\\ ", " ", s)
    for _ in range(4):  # nested font commands and accents
        s = re.sub(r"\\(?:mathbf|boldsymbol|mathrm|text|operatorname)\{([^{}]*)\}", r"\1", s)
        s = re.sub(r"\\bar\{([^{}]*)\}", "\\1\u0304", s)
        s = re.sub(r"\\dot\{([^{}]*)\}", "\\1\u0307", s)
    s = s.replace("^{-1}", "⁻¹").replace("^\\circ", "°")
    arg = r"\{((?:[^{}]|\{[^{}]*\})*)\}"  # a braced argument, one level of braces inside
    for _ in range(3):
        s = re.sub(r"\\sqrt" + arg, r"√(\1)", s)
        s = re.sub(r"\\frac" + arg + arg,
                   lambda m: "/".join(p if re.fullmatch(r"[\w.]+", p) else f"({p})" for p in m.groups()) + " ", s)
    s = re.sub(r"\\([A-Za-z]+)", lambda m: _GREEK.get(m.group(1), m.group(1)), s)
    return re.sub(r"\s+", " ", s).strip()


def transcription(parts):
    """Accessors of a print-parts transcription (``data/paper/<key>/<key>-print-parts.csv``).

    Parameters
    ----------
    parts : pandas.DataFrame
        The transcription: columns ``quantity``, ``value`` (the printed text) and ``line`` (its
        line in the extracted seed).

    Returns
    -------
    text, show, at : callable
        ``text(q)`` the printed text of quantity ``q`` as transcribed; ``show(q)`` the same
        without LaTeX markup (:func:`readable`); ``at(*qs)`` ``"seed line(s) n, m"`` of the quantities.
    """
    pp = parts.set_index("quantity") if "quantity" in parts.columns else parts

    def text(q):
        return str(pp.loc[q, "value"])

    def show(q):
        return readable(text(q))

    def at(*qs):
        lines = sorted({int(pp.loc[q, "line"]) for q in qs})
        return f"seed line{'s' if len(lines) > 1 else ''} {', '.join(map(str, lines))}"

    return text, show, at
