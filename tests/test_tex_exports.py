"""The ``.tex`` exports of ``tables/`` compile with pdflatex in a plain article whose preamble
loads only the packages each export's header names, fit its text width and page height (no
overfull box), and print what the CSV holds: the text of the compiled PDF (``pdftotext``) is
compared, cell by cell, with the table's CSV.

Debian packages: ``texlive-latex-base`` (pdflatex), ``latex-cjk-common`` and
``latex-cjk-chinese-arphic-gbsn00lp`` (``CJKutf8`` and its Chinese font, for the exports with
Chinese text), ``poppler-utils`` (pdftotext); ``scripts/sysdeps.sh`` installs them."""

import json
import os
import re
import shutil
import subprocess
import unicodedata
from collections import defaultdict

import pandas as pd
import pytest

from replication.registry import reproduction as rp

OVERFULL_BOUND_PT = 0.0
"""No box of any export may be overfull, by any amount: the column widths are shares of
``\\linewidth`` that sum to one, every long token has break points, and longtable breaks a tall
table across pages.  (TeX reports an overfull box only beyond ``\\hfuzz`` = 0.1 pt.)"""

MARK = "@@"
"""Printed before each export in the test document, with the table id, to split the PDF's text."""


def preamble(packages) -> str:
    """A plain article loading ``packages`` (and an empty page style, so that no page number enters
    the extracted text; the layout of the page body is the same)."""
    return "\\documentclass{article}\n\\usepackage{" + ",".join(packages) + "}\n\\pagestyle{empty}\n\\begin{document}\n"


def header_packages(tex: str) -> tuple[str, ...]:
    """The packages an export's header names (``%   \\usepackage{...}``)."""
    m = re.search(r"^%\s+\\usepackage\{([^}]*)\}", tex, re.M)
    assert m, "no \\usepackage line in the header"
    return tuple(m.group(1).split(","))


def test_escaping_of_specials_and_unicode():
    assert rp._tex_escape("a_b & 5 % $x$ #1 {y} ~ ^ \\") == (
        r"a\texttt{\char95}b \& 5 \% \$x\$ \#1 \{y\} \texttt{\char126} \texttt{\char94} \textbackslash{}")
    assert rp._tex_escape("a < b > c | d \"e\"") == (
        r"a \textless{} b \textgreater{} c \textbar{} d \texttt{\char34}e\texttt{\char34}")
    assert rp._tex_escape("δK ± 0.3° § 2 μm µs") == (
        r"\ensuremath{\delta}K \ensuremath{\pm} 0.3\textdegree{} \S{} 2 \ensuremath{\mu}m \ensuremath{\mu}s")
    assert rp._tex_escape("x̄ φ̂") == r"\ensuremath{\bar{x}} \ensuremath{\hat{\varphi}}"
    assert rp._tex_escape("ā Ā é") == r"\={a} \={A} \'{e}"
    # pairs TeX would join into one glyph stay two characters
    assert rp._tex_escape("a--b ''c'' x,,y") == "a-{}-b '{}'c'{}' x,{},y"
    # Chinese is kept, in a CJK environment of CJKutf8
    assert rp._tex_escape("误差，ok") == r"\begin{CJK}{UTF8}{gbsn}误差，\end{CJK}ok"
    # a traditional form the GB 2312 font lacks is set in the Big5 font
    assert rp._tex_escape("北銜金") == (r"\begin{CJK}{UTF8}{gbsn}北\end{CJK}\begin{CJK}{UTF8}{bsmi}銜\end{CJK}"
                                      r"\begin{CJK}{UTF8}{gbsn}金\end{CJK}")
    assert all(ord(c) < 128 for c in rp._tex_escape("Ω ≥ √2 ″ ∂ → ∈ ≠ ā Ā ² µ ⊕ ≲ − – —"))
    with pytest.raises(rp.RegistryError, match="U\\+263A"):
        rp._tex_escape("☺")


def test_packages_named_for_what_a_table_holds():
    assert rp.tex_packages("m/s ± 0.1") == ("array", "longtable")
    assert rp.tex_packages("≲ 3 误差") == ("array", "longtable", "CJKutf8", "amssymb")


def _tool(name: str, debian: str):
    exe = shutil.which(name)
    if exe is None:
        if os.environ.get("REPLICATION_REQUIRE_LATEX") == "1":
            pytest.fail(f"{name} not found: install Debian's {debian} (make sysdeps does)")
        pytest.skip(f"{name} not installed (Debian: {debian})")
    return exe


def _compile(exe, folder, name, packages, ids):
    body = "".join(f"\\noindent\\texttt{{{MARK} {i}}}\\par\n\\input{{{i}}}\n\\clearpage\n" for i in ids)
    (folder / f"{name}.tex").write_text(preamble(packages) + body + "\\end{document}\n", encoding="utf-8")
    r = subprocess.run([exe, "-interaction=nonstopmode", "-halt-on-error", f"{name}.tex"], cwd=folder,
                       capture_output=True, text=True, errors="replace", timeout=300)
    return r.returncode == 0, r.stdout[-1500:]


def overfull_boxes(log: str) -> list[tuple[str, float, str]]:
    """``(kind, excess in pt, where)`` of every overfull box reported in a TeX log."""
    return [(m.group(1), float(m.group(2)), m.group(3).strip())
            for m in re.finditer(r"^Overfull \\([hv]box) \(([0-9.]+)pt too (?:wide|high)\) ([^\n]*)", log, re.M)]


@pytest.fixture(scope="module")
def compiled(tmp_path_factory):
    """Every export compiled: one document per set of packages the headers name, each with exactly
    those packages.  ``{packages: (folder, document name, table ids in order)}``."""
    exe = _tool("pdflatex", "texlive-latex-base")
    folder = tmp_path_factory.mktemp("tex")
    files = sorted(rp.tables_dir().glob("*.tex"))
    assert len(files) >= 50, "too few .tex exports"
    groups = defaultdict(list)
    for f in files:
        text = f.read_text(encoding="utf-8")
        groups[header_packages(text)].append(f.stem)
        shutil.copy(f, folder / f.name)
    out = {}
    for k, (packages, ids) in enumerate(sorted(groups.items())):
        name = f"group{k}"
        ok, log = _compile(exe, folder, name, packages, ids)
        if not ok:
            failing = [i for i in ids if not _compile(exe, folder, "one", packages, [i])[0]]
            pytest.fail(f"pdflatex fails with \\usepackage{{{','.join(packages)}}} on {failing[:10]}:\n{log}")
        out[packages] = (folder, name, ids)
    return out


def test_every_tex_export_compiles_in_a_plain_article(compiled):
    assert sum(len(ids) for _, _, ids in compiled.values()) == len(list(rp.tables_dir().glob("*.tex")))
    for packages, (folder, name, ids) in compiled.items():
        assert (folder / f"{name}.pdf").stat().st_size > 5_000
        log = (folder / f"{name}.log").read_text(encoding="latin-1")
        over = [b for b in overfull_boxes(log) if b[1] > OVERFULL_BOUND_PT]
        assert not over, f"{len(over)} overfull boxes beyond {OVERFULL_BOUND_PT} pt, e.g. {over[:5]}"
        assert "Float too large" not in log
        assert "Missing character" not in log


def test_an_export_is_ascii_but_for_chinese_in_cjk_environments():
    for f in sorted(rp.tables_dir().glob("*.tex")):
        text = f.read_text(encoding="utf-8")
        outside = re.sub(r"\\begin\{CJK\}\{UTF8\}\{(gbsn|bsmi)\}[^\\]*\\end\{CJK\}", "", text)
        assert all(ord(c) < 128 for c in outside), f"{f.name}: non-ASCII outside a CJK environment"
        assert ("\\begin{CJK}" in text) == ("CJKutf8" in header_packages(text)), f.name
        assert "[" + "SECTION SIGN]" not in text and "see the CSV]" not in text


# ----------------------------------------------------------------- the PDF's text against the CSV

GLYPH_READINGS = str.maketrans({"\u2019": "'", "\u2018": "`", "\u2206": "\u0394"})
"""What pdftotext reads for a glyph whose name maps to another code point than the CSV's: TeX
prints the ASCII apostrophe and grave as typographic quotes ’ ‘, and Computer Modern's capital
Delta is named ``Delta``, read as U+2206 INCREMENT."""

HYPHEN = "\x00"
"""A hyphen at the end of a line of the PDF's text: TeX's hyphenation (absent from the CSV) or a
hyphen of the text that TeX broke the line after (present)."""


def normalise(text: str) -> str:
    """Text of the CSV or of the PDF in the form compared: NFKC (``µ`` is ``μ``, ``″`` is ``′′``,
    ``…`` is ``...``, ``²`` is ``2``: TeX sets the superscript as a raised digit; ligatures ``ﬁ``
    are ``fi``), :data:`GLYPH_READINGS`, the negation slash that TeX overlays on ``=`` read as
    ``≠``, and no whitespace at all (TeX wraps cells into lines and sets the spaces)."""
    text = text.replace("\u0338=", "\u2260").replace("=\u0338", "\u2260")
    text = unicodedata.normalize("NFKC", text).translate(GLYPH_READINGS)
    return re.sub(r"\s+", "", unicodedata.normalize("NFC", text))


def pdf_text(raw: str) -> str:
    """The text pdftotext extracts (``-raw``: in the order of the content stream, cell after cell),
    with each line-end hyphen after a letter marked :data:`HYPHEN`, normalised."""
    return normalise(re.sub(r"(?<=[^\W\d_])-\n(?=\S)", HYPHEN, raw))


def pattern(expected: str) -> str:
    """A regular expression for the normalised ``expected`` text in :func:`pdf_text`: between any
    two characters a line-end hyphen of hyphenation may stand, and a hyphen of the text may be the
    one a line ended with."""
    return (re.escape(HYPHEN) + "?").join("(?:-|" + re.escape(HYPHEN) + ")" if c == "-" else re.escape(c)
                                          for c in normalise(expected))


def expected_cells(table_id: str) -> tuple[str, list[str], list[list[str]]]:
    """What an export shows, from its CSV: the title (the sidecar's), the header, and per row the
    cells of :data:`~replication.registry.tex.TEX_COLUMNS` as
    :func:`~replication.registry.digits.display_cell` shows them (text columns verbatim;
    numbers with the digits the row's tolerance supports) followed by ``reason:`` and the note."""
    df = pd.read_csv(rp.tables_dir() / f"{table_id}.csv", dtype=str, keep_default_na=False)
    title = json.loads((rp.tables_dir() / f"{table_id}.json").read_text(encoding="utf-8"))["title"]
    header = [rp._HEADINGS.get(c, c) for c, _ in rp.TEX_COLUMNS]
    rows = []
    for _, r in df.iterrows():
        cells = [rp.display_cell(r, c) for c, _ in rp.TEX_COLUMNS]
        if r["note"].strip():
            cells += ["reason:", r["note"].strip()]
        rows.append(cells)
    return title, header, rows


def match(cells, text: str, pos: int = 0) -> int | None:
    """Where ``re.match`` of the concatenated :func:`pattern` of ``cells`` at ``pos`` of ``text`` ends
    (``None``: no match), found as the regular expression's backtracking finds it (the optional
    line-end hyphen taken first, a hyphen of the text read as itself first), without compiling
    one: each cell's pattern is new to ``re``, and compiling them cost more than the rest of the
    comparison."""
    chars = [(c, k > 0) for cell in cells for k, c in enumerate(normalise(cell))]  # (character, hyphen may precede)
    stack = [(0, pos, True)]
    while stack:
        i, p, placed = stack.pop()
        if i == len(chars):
            return p
        c, may_hyphenate = chars[i]
        if not placed and may_hyphenate:
            stack.append((i, p, True))              # tried second: no line-end hyphen here
            if text.startswith(HYPHEN, p):
                stack.append((i, p + 1, True))      # tried first: the line-end hyphen
            continue
        if c == "-" and text.startswith(HYPHEN, p):
            stack.append((i + 1, p + 1, False))
        if text.startswith(c, p):
            stack.append((i + 1, p + 1, False))
    return None


def mismatch(text: str, number: int, table_id: str) -> str | None:
    """``None`` when ``text`` (:func:`pdf_text` of one export, the ``number``-th table of its
    document) is exactly its caption, header and rows from the CSV in order, each row possibly
    preceded by the repeated header of a new page; else where it first differs."""
    title, header, rows = expected_cells(table_id)
    cont = [f"Table {number} (continued)", *header]
    pos = 0
    for what, cells in (("caption", [f"Table {number}:", title]), ("header", header),
                        *((f"row {k + 1}", row) for k, row in enumerate(rows))):
        if what.startswith("row") and (end := match(cont, text, pos)) is not None:
            pos = end
        for cell in cells:
            end = match([cell], text, pos)
            if end is None:
                return f"{what}: expected {cell!r} at …{text[pos:pos + 80]!r}"
            pos = end
    return None if pos == len(text) else f"text after the last row: {text[pos:pos + 80]!r}"


def test_the_pdf_prints_what_the_csv_holds(compiled):
    """pdftotext's text of every export equals its CSV's cells, read as :func:`normalise` says:
    Unicode compatibility forms, three glyph names (:data:`GLYPH_READINGS`), no whitespace, and
    line-end hyphens that may be TeX's; nothing else is allowed (no character missing, replaced or
    added, no placeholder)."""
    exe = _tool("pdftotext", "poppler-utils")
    problems, seen = [], []
    for folder, name, ids in compiled.values():
        raw = subprocess.run([exe, "-raw", "-enc", "UTF-8", f"{name}.pdf", "-"], cwd=folder, capture_output=True,
                             text=True, encoding="utf-8", check=True, timeout=120).stdout
        parts = re.split(rf"^{MARK} (\S+)\n", raw.replace("\f", "\n"), flags=re.M)
        chunks = dict(zip(parts[1::2], parts[2::2]))
        assert list(chunks) == ids, "the exports' texts are not found one after another"
        for number, tid in enumerate(ids, start=1):
            seen.append(tid)
            if (why := mismatch(pdf_text(chunks[tid]), number, tid)) is not None:
                problems.append(f"{tid}: {why}")
    assert len(seen) == len(list(rp.tables_dir().glob("*.tex")))
    assert not problems, f"{len(problems)} exports print other text than their CSV:\n" + "\n".join(problems[:10])


def test_the_comparison_catches_a_wrong_character():
    text = pdf_text("Table 1: t\nquantity unit paper reproduced abs. error tolerance status\n"
                    "a < b m 1 2 3 4 reproduced\n")
    header = "quantityunitpaperreproducedabs.errortolerancestatus"
    assert re.fullmatch(pattern("Table 1: t") + pattern(header) + pattern("a < b"), text[:-len("m1234reproduced")])
    wrong = pdf_text("a ¡ b")
    assert not re.fullmatch(pattern("a < b"), wrong)
    # a hyphenated word and a hyphen at a line end
    assert re.fullmatch(pattern("reproduction"), pdf_text("repro-\nduction"))
    assert re.fullmatch(pattern("not-reproduced"), pdf_text("not-\nreproduced"))
    assert not re.fullmatch(pattern("not-reproduced"), pdf_text("notreproduced"))
    assert normalise("µ ″ … ² ≠") == normalise("μ ′′ . . . 2 \u0338=")


def test_the_matcher_ends_where_the_regular_expression_ends():
    """:func:`match` is :func:`pattern` matched by ``re``: the same end or none, on line-end hyphens
    before, after and inside text hyphens, across cell boundaries and on near misses."""
    import itertools

    cells = (["a-b"], ["-"], ["a-"], ["a", "-"], ["a", "-b"], ["ab", "c"], ["x--y"], ["a-", "-b"], [""], ["é μ"])
    for cs in cells:
        expected = "".join(cs)
        for n in range(0, len(normalise(expected)) + 2):
            for chars in itertools.product(sorted(set(normalise(expected)) | {HYPHEN, "-"}), repeat=n):
                text = "z" + "".join(chars)
                m = re.compile("".join(map(pattern, cs))).match(text, 1)
                assert match(cs, text, 1) == (m.end() if m else None), (cs, text)


def test_export_header_names_the_packages_and_keeps_the_reason():
    df = rp.comparison_frame([
        dict(quantity="q", unit="m", paper=1.0, reproduced=1.5, tolerance=0.1, basis="derivation",
             note="a reason/with/a/very_long_unbreakable_path/in.it", evidence="nb"),
    ])
    tex = rp._latex(df, "t", "chen2019-table-9")
    assert "\\usepackage{array,longtable}" in tex and "\\begin{longtable}" in tex
    assert "\\emph{reason:}" in tex and "very\\texttt{\\char95}\\allowbreak{}long" in tex
    assert "1.5" in tex and "1.0" not in tex
    df.loc[0, "note"] = "误差 ≲ 1"
    assert "\\usepackage{array,longtable,CJKutf8,amssymb}" in rp._latex(df, "t", "chen2019-table-9")


def test_overfull_boxes_are_read_from_the_log():
    log = "x\nOverfull \\hbox (12.5pt too wide) in alignment at lines 10--12\nOverfull \\vbox (3.0pt too high) has occurred\n"
    assert overfull_boxes(log) == [("hbox", 12.5, "in alignment at lines 10--12"), ("vbox", 3.0, "has occurred")]


def test_a_planted_less_than_sign_is_caught_in_the_compiled_pdf(tmp_path):
    """End to end: an export whose ``\\textless`` is written back as a bare ``<`` (what OT1 sets as
    ¡) is compiled and extracted like every export, and the comparison names the cell; the export
    as stored passes."""
    exe, text_exe = _tool("pdflatex", "texlive-latex-base"), _tool("pdftotext", "poppler-utils")
    tid = next(f.stem for f in sorted(rp.tables_dir().glob("*.tex"))
               if "\\textless" in f.read_text(encoding="utf-8") and "CJK" not in f.read_text(encoding="utf-8"))
    good = (rp.tables_dir() / f"{tid}.tex").read_text(encoding="utf-8")
    found = {}
    for name, text in (("stored", good), ("planted", good.replace("\\textless{}", "<").replace("\\textless", "<"))):
        (tmp_path / f"{tid}.tex").write_text(text, encoding="utf-8")
        ok, log = _compile(exe, tmp_path, name, header_packages(text), [tid])
        assert ok, log
        raw = subprocess.run([text_exe, "-raw", "-enc", "UTF-8", f"{name}.pdf", "-"], cwd=tmp_path, capture_output=True,
                             text=True, encoding="utf-8", check=True, timeout=120).stdout
        chunk = re.split(rf"^{MARK} \S+\n", raw.replace("\f", "\n"), flags=re.M)[1]
        found[name] = mismatch(pdf_text(chunk), 1, tid)
    assert found["stored"] is None, found["stored"]
    assert found["planted"] is not None and "<" in found["planted"], found["planted"]
