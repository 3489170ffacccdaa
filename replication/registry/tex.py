"""The TeX form of a comparison table (the ``.tex`` export): the escaping of text (Chinese in
``CJK``, Greek and mathematical signs in math mode, combining accents), the packages a table
needs, and places where a long token may break.
"""

from __future__ import annotations

import re
import unicodedata

import pandas as pd

from replication.registry.digits import display_cell
from replication.registry.markdown import _HEADINGS
from replication.registry.schema import RegistryError

_TEX_SPECIAL = {"\x01": r"\allowbreak{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\texttt{\char95}", "{": r"\{", "}": r"\}",
                "\\": r"\textbackslash{}", "<": r"\textless{}", ">": r"\textgreater{}", "|": r"\textbar{}",
                "~": r"\texttt{\char126}", "^": r"\texttt{\char94}", '"': r"\texttt{\char34}", "`": r"\textasciigrave{}"}
r"""ASCII that TeX does not print as itself in the default (OT1) encoding of a plain article: the
specials escaped; ``< > |`` as the symbols (OT1's slots hold ``¡ ¿ —``); ``~ ^ "``, which OT1 has only
as accents and a closing quote, from the typewriter font, where they are the ASCII glyphs."""


_TEX_LIGATURES = ("--", "''", ",,", "``")
"""Pairs of ASCII characters that TeX fonts join into one glyph (an en dash, a closing or opening
double quote, a low quote): kept apart by ``{}``, so a cell prints ``--`` as two hyphens."""


_GREEK = dict(zip("αβγδεζηθικλμνξπρσςτυφχψωϵϕϑΓΔΘΛΞΠΣΥΦΨΩ",
                  ("alpha", "beta", "gamma", "delta", "varepsilon", "zeta", "eta", "theta", "iota", "kappa", "lambda",
                   "mu", "nu", "xi", "pi", "rho", "sigma", "varsigma", "tau", "upsilon", "varphi", "chi", "psi", "omega",
                   "epsilon", "phi", "vartheta", "Gamma", "Delta", "Theta", "Lambda", "Xi", "Pi", "Sigma", "Upsilon",
                   "Phi", "Psi", "Omega")))


_MATH_SIGNS = {
    "±": "pm", "∓": "mp", "×": "times", "÷": "div", "·": "cdot", "√": "surd", "∇": "nabla", "∂": "partial",
    "∞": "infty", "∝": "propto", "∼": "sim", "≃": "simeq", "≅": "cong", "≡": "equiv", "≈": "approx", "≠": "neq",
    "≥": "geq", "≤": "leq", "≪": "ll", "≫": "gg", "≲": "lesssim", "≳": "gtrsim", "∈": "in", "∉": "notin",
    "⊂": "subset", "⊆": "subseteq", "∩": "cap", "∪": "cup", "∧": "wedge", "∨": "vee", "¬": "neg", "∀": "forall",
    "∃": "exists", "⊥": "perp", "∥": "parallel", "⊕": "oplus", "⊗": "otimes", "∘": "circ", "•": "bullet",
    "⋆": "star", "→": "rightarrow", "←": "leftarrow", "↔": "leftrightarrow", "⇒": "Rightarrow", "⇐": "Leftarrow",
    "⇔": "Leftrightarrow", "↑": "uparrow", "↓": "downarrow", "↦": "mapsto", "ℓ": "ell", "′": "prime",
    "µ": "mu", "∅": "emptyset", "⟨": "langle", "⟩": "rangle", "⌊": "lfloor", "⌋": "rfloor", "⌈": "lceil",
    "⌉": "rceil", **_GREEK,
}
"""Characters set in mathematics mode (``\\ensuremath{\\<name>}``): Greek, operators, relations,
arrows.  ``≲ ≳`` need ``amssymb`` (:data:`TEX_EXTRA_PACKAGES`)."""


_TEX_UNICODE = {
    **{ch: rf"\ensuremath{{\{name}}}" for ch, name in _MATH_SIGNS.items()},
    "°": r"\textdegree{}", "§": r"\S{}", "¶": r"\P{}", "†": r"\dag{}", "‡": r"\ddag{}", "©": r"\copyright{}",
    "¹": r"\ensuremath{^1}", "²": r"\ensuremath{^2}", "³": r"\ensuremath{^3}", "⁻": r"\ensuremath{^-}",
    "⁰": r"\ensuremath{^0}", "⁴": r"\ensuremath{^4}", "⁵": r"\ensuremath{^5}", "⁶": r"\ensuremath{^6}",
    "⁷": r"\ensuremath{^7}", "⁸": r"\ensuremath{^8}", "⁹": r"\ensuremath{^9}",
    "″": r"\ensuremath{''}", "‴": r"\ensuremath{'''}", "−": r"\ensuremath{-}", "–": "--", "—": "---",
    "…": r"\ldots{}", "‘": "`", "’": "'", "“": "``", "”": "''", "\u00a0": "~", "\u2009": r"\,",
    "ß": r"\ss{}", "æ": r"\ae{}", "Æ": r"\AE{}", "œ": r"\oe{}", "Œ": r"\OE{}", "ø": r"\o{}", "Ø": r"\O{}",
    "ı": r"\i{}", "\n": " ", "\t": " ", "¡": r"\textexclamdown{}", "¿": r"\textquestiondown{}",
}
r"""Unicode of the tables in LaTeX that pdflatex sets with the fonts of ``texlive-latex-base``:
Greek and mathematical signs in ``\ensuremath`` (:data:`_MATH_SIGNS`), the others as text
macros.  Accented Latin letters are composed (:data:`_TEX_TEXT_ACCENTS`), Chinese is set by
``CJKutf8``, and any other character is refused (:func:`_tex_escape`)."""


_TEX_TEXT_ACCENTS = {"\u0300": "`", "\u0301": "'", "\u0302": "^", "\u0303": "~", "\u0304": "=", "\u0306": "u",
                     "\u0307": ".", "\u0308": '"', "\u030a": "r", "\u030b": "H", "\u030c": "v", "\u0327": "c",
                     "\u0328": "k"}
"""Combining accents of a precomposed Latin letter (``ā``, ``é``), as LaTeX's text accents."""


_TEX_ACCENTS = {"\u0304": "bar", "\u0302": "hat", "\u0307": "dot", "\u0308": "ddot", "\u0303": "tilde",
                "\u0301": "acute", "\u0300": "grave", "\u030c": "check", "\u0306": "breve", "\u20d7": "vec"}
"""A combining accent written after a symbol (``x̄``, ``φ̂``): the mathematical accent over it."""


TEX_CJK_FONT = "gbsn"
"""The font of Chinese text in a ``.tex`` export (AR PL SungtiL GB, through ``CJKutf8``)."""

TEX_CJK_FALLBACK = "bsmi"
"""The font of a Chinese character that the GB 2312 font lacks (a traditional form such as 銜):
AR PL Mingti2L Big5, through ``CJKutf8``."""


def _cjk_font(ch: str) -> str:
    """:data:`TEX_CJK_FONT` for a character of GB 2312, else :data:`TEX_CJK_FALLBACK` where Big5 has it."""
    for font, codec in ((TEX_CJK_FONT, "gb2312"), (TEX_CJK_FALLBACK, "big5")):
        try:
            ch.encode(codec)
            return font
        except UnicodeEncodeError:
            pass
    return TEX_CJK_FONT


def _fallback_source(text: str) -> str:
    """The header's word on :data:`TEX_CJK_FALLBACK` when ``text`` holds a character only it has."""
    if any(_is_cjk(ch) and _cjk_font(ch) == TEX_CJK_FALLBACK for ch in text):
        return f", and {TEX_CJK_FALLBACK} for characters GB 2312 lacks: latex-cjk-chinese-arphic-bsmi00lp"
    return ""


TEX_EXTRA_PACKAGES = {"≲": "amssymb", "≳": "amssymb"}
"""Characters whose macro needs a package beyond :data:`TEX_PACKAGES` (Chinese needs ``CJKutf8``)."""


def _is_cjk(ch: str) -> bool:
    o = ord(ch)
    return 0x3000 <= o <= 0x303F or 0x3400 <= o <= 0x9FFF or 0xFF00 <= o <= 0xFFEF


def _tex_char(ch: str) -> str:
    """One non-CJK character of a cell in LaTeX (:func:`_tex_escape`)."""
    if ch in _TEX_SPECIAL:
        return _TEX_SPECIAL[ch]
    if " " <= ch <= "~":
        return ch
    if ch in _TEX_UNICODE:
        return _TEX_UNICODE[ch]
    base, *marks = unicodedata.normalize("NFD", ch)
    if marks and all(m in _TEX_TEXT_ACCENTS for m in marks) and ("a" <= base.lower() <= "z"):
        out = "\\i" if base == "i" else base
        for m in marks:
            out = f"\\{_TEX_TEXT_ACCENTS[m]}{{{out}}}"
        return out
    raise RegistryError(f"no LaTeX for the character {ch!r} (U+{ord(ch):04X} {unicodedata.name(ch, '?')}) of a "
                        "table: add it to replication.registry.reproduction._TEX_UNICODE")


def _tex_escape(s: str) -> str:
    r"""Text of a cell in LaTeX that prints it with pdflatex in a plain article: TeX specials and
    the ASCII that OT1 fonts do not hold escaped (:data:`_TEX_SPECIAL`), ligatures of ASCII pairs
    kept apart (:data:`_TEX_LIGATURES`), Greek letters and mathematical signs as macros
    (:data:`_TEX_UNICODE`), accented letters composed, a combining accent over the preceding
    symbol, and each run of Chinese in a ``CJK`` environment of ``CJKutf8`` (font
    :data:`TEX_CJK_FONT`, or :data:`TEX_CJK_FALLBACK` for a character it lacks), left as UTF-8.

    Raises
    ------
    RegistryError
        A character that has no LaTeX here (never printed as a placeholder).
    """
    out: list[str] = []
    i = 0
    while i < len(s):
        ch = s[i]
        if _is_cjk(ch):
            font, j = _cjk_font(ch), i
            while j < len(s) and _is_cjk(s[j]) and _cjk_font(s[j]) == font:
                j += 1
            out.append(rf"\begin{{CJK}}{{UTF8}}{{{font}}}{s[i:j]}\end{{CJK}}")
            i = j
            continue
        if ch in _TEX_ACCENTS and out:
            prev = out.pop()
            inner = prev[len(r"\ensuremath{"):-1] if prev.startswith(r"\ensuremath{") else prev
            out.append(rf"\ensuremath{{\{_TEX_ACCENTS[ch]}{{{inner}}}}}")
        else:
            piece = _tex_char(ch)
            if out and out[-1][-1:] + piece[:1] in _TEX_LIGATURES:
                out[-1] += "{}"
            out.append(piece)
        i += 1
    return "".join(out)


def tex_packages(text: str) -> tuple[str, ...]:
    r"""The LaTeX packages a document needs to set ``text`` as ``_tex_escape`` writes it:
    :data:`TEX_PACKAGES`, ``amssymb`` for a sign of :data:`TEX_EXTRA_PACKAGES`, ``CJKutf8`` for
    Chinese.

    Parameters
    ----------
    text : str
        Every cell of an export.

    Returns
    -------
    tuple of str
        Package names, in the order of a ``\usepackage`` line.
    """
    extra = {p for ch, p in TEX_EXTRA_PACKAGES.items() if ch in text}
    if any(_is_cjk(ch) for ch in text):
        extra.add("CJKutf8")
    return (*TEX_PACKAGES, *sorted(extra))


TEX_PACKAGES = ("array", "longtable")
r"""The LaTeX packages every export ``tables/<id>.tex`` needs (both in LaTeX's tools bundle:
Debian's ``texlive-latex-base``); an export with Chinese text or a sign of
:data:`TEX_EXTRA_PACKAGES` names more in its header (:func:`tex_packages`)."""


_TEX_PACKAGE_SOURCES = {"CJKutf8": "CJKutf8: Debian's latex-cjk-common, its font gbsn: latex-cjk-chinese-arphic-gbsn00lp",
                        "amssymb": "amssymb: texlive-base"}


TEX_COLUMNS = (("quantity", 0.16), ("unit", 0.11), ("paper", 0.16), ("reproduced", 0.16),
               ("abs_error", 0.135), ("tolerance", 0.115), ("status", 0.16))
r"""The columns of a ``.tex`` export and their shares of ``\linewidth``; the reason (the ``note``)
follows each row on a line of the full width."""


_BREAK = "\x01"          # a place where TeX may break a long token (``\allowbreak``)


_LONG_TOKEN = 9


def _tex_breakable(text: str, long: int = _LONG_TOKEN) -> str:
    """``text`` with break points in tokens longer than ``long`` characters: after ``/ _ . , ; : =
    +`` and closing brackets, and before the exponent of a number."""
    out = []
    for tok in re.split(r"(\s+)", text):
        if len(tok) > long and not tok.isspace():
            if re.fullmatch(r"[-+]?\d[\d.]*[eE][-+]?\d+", tok):
                tok = re.sub(r"([eE])", _BREAK + r"\1", tok)
            elif re.fullmatch(r"[-+]?\d+\.\d+", tok):        # a long decimal: breaks every four decimals
                head, tail = tok.split(".")
                tok = head + "." + _BREAK.join(tail[i:i + 4] for i in range(0, len(tail), 4))
            else:
                tok = re.sub(r"([/_.,;:=+)\]}])(?=[^\s])", r"\1" + _BREAK, tok)
        out.append(tok)
    return "".join(out)


def _tex_cell(text: str, long: int = _LONG_TOKEN) -> str:
    """A cell of a ``.tex`` export: escaped (:func:`_tex_escape`), with break points in tokens
    longer than ``long`` characters."""
    return _tex_escape(_tex_breakable(text, long))


def _latex(df: pd.DataFrame, title: str, table_id: str) -> str:
    r"""The ``.tex`` export of a comparison table: a ``longtable`` that fits the text width of a
    plain ``article`` (``p`` columns, long cells wrapped) and breaks across pages, its header
    repeated; each row's reason (the ``note``) on a line of the full width below it.  Needs
    ``\usepackage{array,longtable}`` (:data:`TEX_PACKAGES`), and the packages :func:`tex_packages`
    adds (``CJKutf8`` for Chinese text, ``amssymb`` for ``≲ ≳``), all named in its header."""
    n = len(TEX_COLUMNS)
    # ragged right, and hyphenable from the first word of a cell on (``\hspace{0pt}``)
    left = r">{\raggedright\arraybackslash\hspace{0pt}}"
    spec = "".join(rf"{left}p{{\dimexpr {w}\linewidth-2\tabcolsep\relax}}" for _, w in TEX_COLUMNS)
    full = left + r"p{\dimexpr\linewidth-2\tabcolsep\relax}"
    header = " & ".join(_tex_escape(_HEADINGS.get(c, c)) for c, _ in TEX_COLUMNS) + r" \\"
    rows = [[display_cell(r, c) for c, _ in TEX_COLUMNS] + [str(r.get("note", "") or "").strip()] for _, r in df.iterrows()]
    packages = tex_packages(" ".join([title, *(cell for row in rows for cell in row)]))
    lines = [
        f"% tables/{table_id}.tex: {_tex_escape(title)}",
        "% Written by replication.registry.reproduction from tables/" + table_id + ".csv (which keeps every stored",
        "% digit); regenerate with replication.registry.exports.refresh_exports().  UTF-8; compiles with pdflatex.",
        "% Include with \\input{" + table_id + "} in a document whose preamble has",
        "%   \\usepackage{" + ",".join(packages) + "}",
        "% (array and longtable: LaTeX's tools bundle, Debian's texlive-latex-base"
        + "".join(f"; {_TEX_PACKAGE_SOURCES[p]}" for p in packages if p in _TEX_PACKAGE_SOURCES)
        + _fallback_source(" ".join([title, *(cell for row in rows for cell in row)])) + ");",
        "% the table fits the text width of a plain article, breaks across pages and repeats its header.",
        r"\begingroup",
        r"\footnotesize",
        r"\setlength{\tabcolsep}{2pt}",
        r"\begin{longtable}{" + spec + "}",
        rf"\caption{{{_tex_escape(title)}}}\label{{tab:{table_id}}}\\",
        r"\hline", header, r"\hline", r"\endfirsthead",
        rf"\multicolumn{{{n}}}{{l}}{{\emph{{Table \thetable{{}} (continued)}}}}\\",
        r"\hline", header, r"\hline", r"\endhead",
        r"\hline", r"\endfoot",
    ]
    for *shown, note in rows:
        cells = " & ".join(_tex_cell(text, 4 if c == "unit" else _LONG_TOKEN) for text, (c, _) in zip(shown, TEX_COLUMNS))
        if note:
            lines.append(cells + r" \\*")
            lines.append(rf"\multicolumn{{{n}}}{{{full}}}{{\hspace*{{1em}}\emph{{reason:}} {_tex_cell(note)}}} \\[2pt]")
        else:
            lines.append(cells + r" \\")
    lines += [r"\end{longtable}", r"\endgroup"]
    return "\n".join(lines) + "\n"
