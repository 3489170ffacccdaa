"""The ``.tex`` exports of ``tables/`` compile with pdflatex in a plain article (Debian's
``texlive-latex-base``), and the escaping of a cell is right."""

import os
import shutil
import subprocess

import pytest

from replication.registry import reproduction as rp

PREAMBLE = "\\documentclass{article}\n\\begin{document}\n"


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
