"""The ``.tex`` exports of ``tables/`` compile with pdflatex in a plain article (Debian's
``texlive-latex-base``) whose preamble loads only the packages each export's header names, fit its
text width and page height (no overfull box), and the escaping of a cell is right."""

import os
import re
import shutil
import subprocess

import pytest

from replication.registry import reproduction as rp

PREAMBLE = "\\documentclass{article}\n\\usepackage{" + ",".join(rp.TEX_PACKAGES) + "}\n\\begin{document}\n"

OVERFULL_BOUND_PT = 0.0
"""No box of any export may be overfull, by any amount: the column widths are shares of
``\\linewidth`` that sum to one, every long token has break points, and longtable breaks a tall
table across pages.  (TeX reports an overfull box only beyond ``\\hfuzz`` = 0.1 pt.)"""


def test_escaping_of_specials_and_unicode():
    assert rp._tex_escape("a_b & 5 % $x$ #1 {y} ~ ^ \\") == (
        r"a\_b \& 5 \% \$x\$ \#1 \{y\} \textasciitilde{} \textasciicircum{} \textbackslash{}")
    assert rp._tex_escape("δK ± 0.3°") == r"\ensuremath{\delta}K \ensuremath{\pm} 0.3\textdegree{}"
    assert rp._tex_escape("x̄ φ̂") == r"\ensuremath{\bar{x}} \ensuremath{\hat{\varphi}}"
    assert rp._tex_escape("误差 ok") == "[Chinese text: see the CSV] ok"
    assert all(ord(c) < 128 for c in rp._tex_escape("Ω ≥ √2 ″ ∂ → ∈ ≠ ā Ā ² µ ⊕"))


def _pdflatex():
    exe = shutil.which("pdflatex")
    if exe is None:
        if os.environ.get("REPLICATION_REQUIRE_LATEX") == "1":
            pytest.fail("pdflatex not found: install Debian's texlive-latex-base (make sysdeps does)")
        pytest.skip("pdflatex not installed (Debian: texlive-latex-base)")
    return exe


def _compile(exe, tmp_path, names):
    doc = PREAMBLE + "".join(f"\\input{{{n}}}\n\\clearpage\n" for n in names) + "\\end{document}\n"
    (tmp_path / "all.tex").write_text(doc, encoding="ascii")
    r = subprocess.run([exe, "-interaction=nonstopmode", "-halt-on-error", "all.tex"], cwd=tmp_path,
                       capture_output=True, text=True, errors="replace", timeout=300)
    return r.returncode == 0, r.stdout[-1500:]


def overfull_boxes(log: str) -> list[tuple[str, float, str]]:
    """``(kind, excess in pt, where)`` of every overfull box reported in a TeX log."""
    return [(m.group(1), float(m.group(2)), m.group(3).strip())
            for m in re.finditer(r"^Overfull \\([hv]box) \(([0-9.]+)pt too (?:wide|high)\) ([^\n]*)", log, re.M)]


def test_every_tex_export_compiles_in_a_plain_article(tmp_path):
    exe = _pdflatex()
    files = sorted(rp.tables_dir().glob("*.tex"))
    assert len(files) >= 50, "too few .tex exports"
    for f in files:
        text = f.read_text(encoding="utf-8")
        assert all(ord(c) < 128 for c in text), f"{f.name}: non-ASCII characters left"
        shutil.copy(f, tmp_path / f.name)
    ok, log = _compile(exe, tmp_path, [f.stem for f in files])
    if not ok:
        failing = [f.name for f in files if not _compile(exe, tmp_path, [f.stem])[0]]
        pytest.fail(f"pdflatex fails on {failing[:10]}:\n{log}")
    assert (tmp_path / "all.pdf").stat().st_size > 10_000
    log = (tmp_path / "all.log").read_text(encoding="latin-1")
    over = [b for b in overfull_boxes(log) if b[1] > OVERFULL_BOUND_PT]
    assert not over, f"{len(over)} overfull boxes beyond {OVERFULL_BOUND_PT} pt, e.g. {over[:5]}"
    assert "Float too large" not in log


def test_export_header_names_the_packages_and_keeps_the_reason():
    df = rp.comparison_frame([
        dict(quantity="q", unit="m", paper=1.0, reproduced=1.5, tolerance=0.1, status="erratum",
             note="a reason/with/a/very_long_unbreakable_path/in.it", evidence="nb"),
    ])
    tex = rp._latex(df, "t", "chen2019-table-9")
    assert "\\usepackage{array,longtable}" in tex and "\\begin{longtable}" in tex
    assert "\\emph{reason:}" in tex and "very\\_\\allowbreak{}long" in tex.replace("very\\_long", "very\\_\\allowbreak{}long")
    assert "1.5" in tex and "1.0" not in tex


def test_overfull_boxes_are_read_from_the_log():
    log = "x\nOverfull \\hbox (12.5pt too wide) in alignment at lines 10--12\nOverfull \\vbox (3.0pt too high) has occurred\n"
    assert overfull_boxes(log) == [("hbox", 12.5, "in alignment at lines 10--12"), ("vbox", 3.0, "has occurred")]
