"""The reproduction registry: paper-value files, comparisons, exports, index and CLI."""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import replication
from replication.__main__ import main as cli
from replication.registry import reproduction as rp

ROOT = Path(__file__).resolve().parent.parent

GOOD = """# document: chen2019
# location: Table 9-9
# section: ch. 9 §1
# notes: a test file
quantity,unit,value,note
alpha,m,1.5,
beta,°,0.0025,
range,m,0.05~0.3,kept as text
"""


@pytest.fixture()
def sandbox(tmp_path, monkeypatch):
    """A throw-away project root with data/ and tables/ so tests never touch the real ones."""
    (tmp_path / "data" / "paper" / "chen2019").mkdir(parents=True)
    (tmp_path / "tables").mkdir()
    shutil.copy(ROOT / "data" / "sources.bib", tmp_path / "data" / "sources.bib")
    (tmp_path / "data" / "artifacts.csv").write_text(
        "id,source,artifact,description\nchen2019-table-9-9,chen2019,Table 9-9,a test table\n"
        "chen2019-table-9-8,chen2019,Table 9-8,never exported\n",
        encoding="utf-8",
    )
    (tmp_path / "data" / "paper" / "chen2019" / "chen2019-table-9-9.csv").write_text(GOOD, encoding="utf-8")
    # the notebook and the tests that the sandbox tables name as evidence (the audit checks they exist)
    (tmp_path / "book").mkdir()
    (tmp_path / "book" / "x.ipynb").write_text("{}", encoding="utf-8")
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "test_x.py").write_text("def test_beta():\n    pass\n", encoding="utf-8")
    (tmp_path / "tests" / "t.py").write_text("def t():\n    pass\n", encoding="utf-8")
    monkeypatch.setenv("REPLICATION_ROOT", str(tmp_path))
    return tmp_path


def test_load_paper_reads_values_and_provenance(sandbox):
    p = rp.load_paper("chen2019-table-9-9")
    assert p.provenance["location"] == "Table 9-9"
    assert p.value("alpha") == 1.5
    assert p.value("range") == "0.05~0.3"
    assert math.isnan(p.numeric()["range"])
    assert p.unit("beta") == "°"


@pytest.mark.parametrize(
    "text, message",
    [
        (GOOD.replace("# section: ch. 9 §1\n", ""), "missing provenance"),
        (GOOD.replace("# document: chen2019", "# document: smith1999"), "is not one of"),
        ("# document: chen2019\n# location: x\n# section: y\n# notes: z\nquantity,value\na,1\n", "needs a column 'unit'"),
        (GOOD + "alpha,m,2,\n", "duplicated quantities"),
        ("# document: chen2019\n# location: x\n# section: y\n# notes: z\n", "no CSV body"),
        (GOOD.replace("# notes: a test file", "#notes a test file"), "provenance lines look like"),
    ],
)
def test_malformed_paper_files_fail_clearly(sandbox, text, message):
    path = sandbox / "data" / "paper" / "chen2019" / "chen2019-table-9-7.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(rp.RegistryError, match=message):
        rp.parse_paper_file(path)


def test_unknown_and_malformed_ids(sandbox):
    with pytest.raises(rp.RegistryError, match="no paper values"):
        rp.load_paper("chen2019-table-9-1")
    with pytest.raises(rp.RegistryError, match="malformed table id"):
        rp.load_paper("Chen2019 table 1")


def test_status_is_computed_from_the_tolerance():
    df = rp.comparison_frame([
        dict(quantity="in", unit="m", paper=1.0, reproduced=1.0004, tolerance=1e-3),
        dict(quantity="out", unit="m", paper=1.0, reproduced=1.01, tolerance=1e-3),
        dict(quantity="rel", unit="m", paper=100.0, reproduced=101.0, tolerance=0.02, tolerance_kind="rel"),
    ])
    assert list(df["status"]) == ["reproduced", "not-reproduced", "reproduced"]
    assert float(df.loc[1, "abs_error"]) == pytest.approx(0.01, rel=1e-12)
    assert df.loc[2, "tolerance"] == "0.02" and df.loc[2, "tolerance_kind"] == "rel"
    assert rp.display_cell(df.loc[2], "tolerance") == "0.02 (rel)"
    assert df.loc[0, "tolerance_kind"] == "abs"


def test_numeric_columns_hold_only_numbers():
    df = rp.comparison_frame([
        dict(quantity="range", unit="m", paper="4.0~6.0", reproduced=5.0, basis="verdict", agrees=True, note="inside"),
        dict(quantity="word", unit="", paper=1.0, reproduced="decreasing", basis="verdict", agrees=True, note="shape"),
        dict(quantity="num", unit="m", paper=2.0, reproduced=2.0, tolerance=0.1),
    ])
    for col in rp.NUMERIC_COLUMNS:
        for v in df[col]:
            assert v == "" or math.isfinite(float(v)), (col, v)
    assert df.loc[0, "paper"] == "" and df.loc[0, "paper_text"] == "4.0~6.0"
    assert df.loc[1, "reproduced"] == "" and df.loc[1, "reproduced_text"] == "decreasing"
    assert rp.display_cell(df.loc[0], "paper") == "4.0~6.0"


def test_precision_policy_stores_only_determined_digits():
    # round-off-level differences (relative 1e-5 of an ideal-flight error, a few 1e-15 of a
    # numerical Jacobian) must not change the stored text; the tolerance sets the grid
    a = rp.comparison_frame([dict(quantity="e", unit="m", paper=0.0, reproduced=1.457058959e-4, tolerance=0.05),
                             dict(quantity="j", unit="SI", paper=0.0, reproduced=3.25e-15, tolerance=7.349899533e-13)])
    b = rp.comparison_frame([dict(quantity="e", unit="m", paper=0.0, reproduced=1.457070961e-4, tolerance=0.05),
                             dict(quantity="j", unit="SI", paper=0.0, reproduced=4.34e-15, tolerance=7.349899501e-13)])
    assert a.equals(b)
    assert a.loc[0, "reproduced"] == "0" and a.loc[1, "reproduced"] == "0"  # grids 1e-3 m and 1e-14
    assert a.loc[1, "tolerance"] == "7.35e-13"
    # a row without a tolerance keeps DEFAULT_DIGITS significant digits, ``digits`` overrides
    c = rp.comparison_frame([dict(quantity="x", unit="", paper=1.0, reproduced=1.23456789, basis="stand-in", agrees=True, note="n"),
                             dict(quantity="y", unit="", paper=1.0, reproduced=1.23456789, basis="stand-in", agrees=True, note="n",
                                  digits=3)])
    assert c.loc[0, "reproduced"] == "1.23457" and c.loc[1, "reproduced"] == "1.23"
    # a tight tolerance keeps the digits it needs: the comparison is read to a tenth of it
    d = rp.comparison_frame([dict(quantity="g", unit="m/s^2", paper=9.7803267714, reproduced=9.78032677141234,
                                  tolerance=1e-9)])
    assert d.loc[0, "reproduced"] == "9.7803267714" and d.loc[0, "status"] == "reproduced"
    # errors are recomputed exactly from the stored values
    assert float(d.loc[0, "abs_error"]) == 0.0
    with pytest.raises(rp.RegistryError, match="positive integer"):
        rp.comparison_frame([dict(quantity="z", unit="", paper=1, reproduced=1, tolerance=1, digits=0)])
    with pytest.raises(rp.RegistryError, match="unknown keys"):
        rp.comparison_frame([dict(quantity="z", unit="", paper=1, reproduced=1, tolerence=1)])


def test_every_row_declares_its_basis():
    """A row's status follows from its basis and evidence; a row without basis (and not a value row
    with a tolerance, which gets basis ``value``) is refused, a typed status with it."""
    for row in (dict(quantity="q", unit="", paper="up", reproduced="up", status="qualitative", note="n"),
                dict(quantity="q", unit="", paper=1, reproduced=2, status="erratum", note="typo", evidence="e"),
                dict(quantity="q", unit="", paper=1, reproduced=1.0, tolerance=0.1, status="reproduced"),
                dict(quantity="q", unit="", paper=1, reproduced=2)):
        with pytest.raises(rp.RegistryError, match="chen2019-table-9-9: row 'q' declares no basis"):
            rp.comparison_frame([row], "chen2019-table-9-9")
    with pytest.raises(rp.RegistryError, match="status='qualitative' is not evidence"):
        rp.comparison_frame([dict(quantity="q", unit="", paper="up", reproduced="up", status="qualitative", note="n")])
    with pytest.raises(rp.RegistryError, match="drop status"):
        rp.comparison_frame([dict(quantity="q", unit="", paper="up", reproduced="up", status="qualitative",
                                  basis="verdict", agrees=True, note="n")])
    with pytest.raises(rp.RegistryError, match="needs a note"):
        rp.comparison_frame([dict(quantity="q", unit="", paper="up", reproduced="down", basis="verdict", agrees=False)])
    with pytest.raises(rp.RegistryError, match="unknown basis"):
        rp.comparison_frame([dict(quantity="q", unit="", paper=1, reproduced=2, basis="fine", note="x")])
    with pytest.raises(rp.RegistryError, match="appears twice"):
        rp.comparison_frame([dict(quantity="q", unit="", paper=1, reproduced=1, tolerance=1)] * 2)
    assert rp.comparison_frame([dict(quantity="q", unit="", paper=1, reproduced=1, tolerance=1)])["basis"].tolist() \
        == ["value"]


def test_compare_refuses_a_row_without_basis_and_writes_nothing(sandbox):
    with pytest.raises(rp.RegistryError, match="chen2019-table-9-9: row 'q' declares no basis"):
        rp.compare("chen2019-table-9-9", [dict(quantity="q", unit="", paper="up", reproduced="up",
                                               status="qualitative", note="shape")],
                   title="T", notebook="book/x.ipynb")
    assert not (sandbox / "tables" / "chen2019-table-9-9.csv").exists()


def test_compare_exports_all_formats_and_is_idempotent(sandbox):
    rows = [
        dict(quantity="alpha", unit="m", paper=1.5, reproduced=1.5000001, tolerance=1e-6),
        dict(quantity="beta", unit="°", paper=0.0025, reproduced=0.0035, basis="derivation",
             note="prose says 0.0035", evidence="tests/test_x.py::test_beta", tolerance=1e-4),
    ]
    df = rp.compare("chen2019-table-9-9", rows, title="Test table", notebook="book/x.ipynb", seeds={"mc": 1})
    assert list(df.columns) == list(rp.TABLE_COLUMNS)
    for ext in (".csv", ".md", ".tex", ".json"):
        assert (sandbox / "tables" / f"chen2019-table-9-9{ext}").exists()
    meta = json.loads((sandbox / "tables" / "chen2019-table-9-9.json").read_text(encoding="utf-8"))
    assert meta["paper_source"] == "data/paper/chen2019/chen2019-table-9-9.csv"
    assert meta["seeds"] == {"mc": 1} and meta["packages"]["numpy"] != "absent"
    assert meta["status_counts"]["erratum"] == 1
    stamp = {p.name: p.stat().st_mtime_ns for p in (sandbox / "tables").iterdir()}
    rp.compare("chen2019-table-9-9", rows, title="Test table", notebook="book/x.ipynb", seeds={"mc": 1})
    assert stamp == {p.name: p.stat().st_mtime_ns for p in (sandbox / "tables").iterdir()}
    back = rp.read_table("chen2019-table-9-9")
    assert back.loc[0, "status"] == "reproduced"


def test_index_lists_every_artifact_and_collects_the_register(sandbox):
    rows = [dict(quantity="beta", unit="°", paper=0.0025, reproduced=0.0035, basis="derivation", agrees=False,
                 note="prose says 0.0035", evidence="tests/test_x.py::test_beta"),
            dict(quantity="alpha", unit="m", paper=1.5, paper_text="1.5 (caption: 2.5)", reproduced=1.5,
                 basis="parts", agrees=False, note="the caption prints 2.5, the table 1.5")]
    rp.compare("chen2019-table-9-9", rows, title="T", notebook="book/x.ipynb")
    rp.compare("chen2019-check-extra", [dict(quantity="q", unit="", paper=1, reproduced=1, tolerance=0)],
               title="Extra", notebook="book/x.ipynb")
    status, register = rp.build_index()
    assert list(status["id"]) == ["chen2019-table-9-9", "chen2019-table-9-8", "chen2019-check-extra"]
    assert list(status["status"]) == ["erratum", "pending", "reproduced"]
    assert status.iloc[2]["artifact"] == "supplementary"
    assert list(register["kind"]) == ["erratum", "inconsistent"]           # both kinds, one register
    assert register.iloc[0]["evidence"] == "tests/test_x.py::test_beta"
    assert register.iloc[1]["printed"] == "1.5 (caption: 2.5)"             # the print as printed
    on_disk = pd.read_csv(sandbox / "tables" / "register.csv", dtype=str, keep_default_na=False)
    assert tuple(on_disk.columns) == rp.REGISTER_COLUMNS
    assert not (sandbox / "tables" / "errata.csv").exists()
    desc = {f["name"]: f.get("description") for r in rp.datapackage()["resources"] if r["name"] == "register"
            for f in r["schema"]["fields"]}
    assert desc["kind"] and desc["printed"]


LEDGER_ROW = {"qualitative": dict(basis="verdict", agrees=True), "not-reproduced": dict(basis="verdict", agrees=False)}
"""The evidence of a ledger row that reaches the print (``qualitative``) or misses it."""


def _main_and_ledger(ledger_status="qualitative", ledger_value=2.0, **kw):
    """A main table with one row that misses the print under its main reading, and a readings
    ledger with the main reading and one other; the ledger is exported first, as a chapter must."""
    rp.compare("chen2019-check-table-9-9-readings",
               [dict(quantity="main | alpha", unit="m", paper=1.5, reproduced=3.0, tolerance=0.1, note="misses"),
                dict(quantity="other convention | alpha", unit="m", paper=1.5, reproduced=ledger_value,
                     **({"tolerance": 0.1} if ledger_status is None else {**LEDGER_ROW[ledger_status], "note": "n"}))],
               title="ledger", notebook="book/x.ipynb")
    return rp.compare("chen2019-table-9-9", [dict(quantity="alpha", unit="m", paper=1.5, reproduced=3.0,
                                                  tolerance=0.1, note="misses the print")],
                      title="T", notebook="book/x.ipynb", **kw)


def test_a_reading_that_reaches_the_print_makes_a_miss_unverifiable(sandbox):
    """The status follows from the ledger: a reading the print leaves open reaches the printed value,
    so the row is not 'not-reproduced' (every faithful reading would have to miss)."""
    df = _main_and_ledger(main_reading="main", reading_evidence="the printed numbers of column 2 (1.5)")
    assert df.set_index("quantity").loc["alpha", "status"] == "unverifiable"
    assert rp.verdict_violations() == []
    df = _main_and_ledger(ledger_value=2.0, ledger_status="not-reproduced", main_reading="main",
                          reading_evidence="the printed numbers of column 2 (1.5)")
    assert df.set_index("quantity").loc["alpha", "status"] == "not-reproduced"


def test_a_stored_status_that_its_ledger_contradicts_is_refused(sandbox):
    """A main table stored before its ledger changed (or edited by hand with its digest forged):
    index re-derives the status and refuses the stored one, naming table, row and reason."""
    rp.compare("chen2019-table-9-9", [dict(quantity="alpha", unit="m", paper=1.5, reproduced=3.0, tolerance=0.1,
                                           note="misses")], title="T", notebook="book/x.ipynb",
               main_reading="main", reading_evidence="the printed numbers of column 2 (1.5)")
    rp.compare("chen2019-check-table-9-9-readings",
               [dict(quantity="main | alpha", unit="m", paper=1.5, reproduced=3.0, tolerance=0.1, note="misses"),
                dict(quantity="other convention | alpha", unit="m", paper=1.5, reproduced=1.55, tolerance=0.1)],
               title="ledger", notebook="book/x.ipynb")
    bad = rp.verdict_violations()
    assert len(bad) == 1 and "'alpha'" in bad[0] and "gives unverifiable" in bad[0], bad
    with pytest.raises(rp.RegistryError, match="verdict rule"):
        rp.build_index()
    assert cli(["index"]) == 2


def test_verdict_rule_reads_the_tolerance_of_the_main_row(sandbox):
    """A ledger row whose own status says nothing still reaches the print within the row's tolerance."""
    df = _main_and_ledger(ledger_status=None, ledger_value=1.55, main_reading="main", reading_evidence="e (1.5)")
    assert df["status"].tolist() == ["unverifiable"]
    df = _main_and_ledger(ledger_status=None, ledger_value=1.7, main_reading="main", reading_evidence="e (1.5)")
    assert df["status"].tolist() == ["not-reproduced"]                   # 0.2 > 0.1: it misses too
    assert rp.verdict_violations() == []


def test_verdict_rule_accepts_a_reading_ruled_out_by_printed_evidence(sandbox):
    """A reading that printed numbers exclude does not threaten the verdict; the sentence must quote
    a printed value (alpha = 1.5 of the paper file)."""
    df = _main_and_ledger(main_reading="main", reading_evidence="column 2 identifies the main convention (1.5)",
                          ruled_out={"other": "the printed alpha = 1.5 m contradicts the other convention"})
    assert df["status"].tolist() == ["not-reproduced"]
    assert rp.verdict_violations() == []
    status, _ = rp.build_index()
    fail = rp.failing_artifacts(status)
    assert list(fail["id"]) == ["chen2019-table-9-9"] and fail.iloc[0]["reason"]
    _main_and_ledger(main_reading="main", reading_evidence="column 2 (1.5)",
                     ruled_out={"other": "we think it unlikely"})
    assert any("quotes no printed value" in v for v in rp.verdict_violations())


def test_verdict_rule_needs_a_main_reading_and_a_named_reading(sandbox):
    _main_and_ledger(ledger_status="not-reproduced")
    assert any("no main_reading" in v for v in rp.verdict_violations())
    _main_and_ledger(ledger_status="not-reproduced", main_reading="main", reading_evidence="e",
                     ruled_out={"a reading nobody tried": "alpha = 1.5 m"})
    assert any("is no reading" in v for v in rp.verdict_violations())
    with pytest.raises(rp.RegistryError, match="together"):
        rp.compare("chen2019-table-9-9", [dict(quantity="a", unit="", paper=1, reproduced=1, tolerance=0)],
                   title="T", notebook="book/x.ipynb", main_reading="main")


def test_verdict_rule_refuses_an_erratum_that_a_reading_reproduces(sandbox):
    """A 'misprint' that another printed part (a reading) reproduces is an inconsistency: typed as
    erratum it is refused; declared as a derivation it is derived inconsistent."""
    rp.compare("chen2019-check-table-9-9-readings",
               [dict(quantity="the table's convention | alpha", unit="m", paper=1.5, reproduced=1.5, tolerance=0.1)],
               title="ledger", notebook="book/x.ipynb")
    with pytest.raises(rp.RegistryError, match="chen2019-table-9-9: row 'alpha' declares no basis"):
        rp.compare("chen2019-table-9-9", [dict(quantity="alpha", unit="m", paper=1.5, reproduced=3.0, tolerance=0.1,
                                               status="erratum", note="n", evidence="tests/t.py::t")],
                   title="T", notebook="book/x.ipynb", main_reading="main", reading_evidence="e")
    df = rp.compare("chen2019-table-9-9", [dict(quantity="alpha", unit="m", paper=1.5, reproduced=3.0, tolerance=0.1,
                                                basis="derivation", note="n", evidence="tests/t.py::t")],
                    title="T", notebook="book/x.ipynb", main_reading="main", reading_evidence="e")
    assert df["status"].tolist() == ["inconsistent"]


def test_the_stored_tables_obey_the_verdict_rule():
    """Every exported table of the project: no not-reproduced or erratum row that a reading of its
    ledger reproduces without printed evidence ruling that reading out."""
    assert rp.verdict_violations() == []


def test_roll_up_rules():
    """CONTRIBUTING.md, "Statuses": errata and inconsistencies are counted beside the status and
    never decide it; one marginal row does not stand for a whole table (``mixed``, split shown)."""
    s = rp.summarize_status
    assert s(["reproduced"] * 3 + ["erratum"] * 52) == "reproduced"          # errata do not hide, nor decide
    assert s(["analog", "erratum"]) == "analog"
    assert s(["reproduced"] * 25 + ["not-reproduced"]) == "mixed"           # not the weakest row
    assert s(["reproduced", "qualitative"]) == "reproduced"
    assert s(["qualitative", "qualitative"]) == "qualitative"
    assert s(["not-reproduced", "not-reproduced", "inconsistent"]) == "not-reproduced"
    assert s(["erratum", "erratum"]) == "erratum" and s(["inconsistent"]) == "inconsistent"
    assert s(["pending", "erratum"]) == "pending" and s([]) == "pending"
    assert s(["reproduced", "pending"]) == "mixed"
    with pytest.raises(rp.RegistryError, match="unknown status"):
        s(["fine"])
    row = {"status": "reproduced", "erratum": 52, "inconsistent": 1}
    assert rp.status_label(row) == "reproduced, 52 errata, 1 inconsistency"
    mixed = {"status": "mixed", "reproduced": 20, "not_reproduced": 3, "analog": 1, "erratum": 2}
    assert rp.status_label(mixed) == "mixed (3 not-reproduced, 1 analog, 20 reproduced), 2 errata"   # split, failures first


def test_cli_show_cite_and_unknown_id(sandbox, capsys):
    rp.compare("chen2019-table-9-9", [dict(quantity="alpha", unit="m", paper=1.5, reproduced=1.5, tolerance=0)],
               title="Test table", notebook="book/x.ipynb")
    assert cli(["show", "chen2019-table-9-9", "--format", "csv"]) == 0
    assert "alpha,m,1.5,,1.5,,0,0,0,abs,reproduced" in capsys.readouterr().out
    assert cli(["show", "chen2019-table-9-9", "--format", "tex"]) == 0
    assert r"\begin{longtable}" in capsys.readouterr().out
    assert cli(["cite", "chen2019-table-9-9"]) == 0
    out = capsys.readouterr().out
    assert "@misc{repro-chen2019-table-9-9," in out and "@techreport{chen2019," in out
    assert cli(["show", "chen2019-table-4-99"]) == 2
    assert "no exported table" in capsys.readouterr().err
    assert cli(["status"]) == 0
    out = capsys.readouterr().out
    assert "2 paper artifacts" in out and "reproduced" in out


def test_cli_runs_as_module_on_the_real_project():
    out = subprocess.run([sys.executable, "-m", "replication", "status"], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout
    arts = rp.load_artifacts()
    for tid in arts["id"]:
        assert tid in out
    bad = subprocess.run([sys.executable, "-m", "replication", "cite", "an2021-table-77"], cwd=ROOT,
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "error:" in bad.stderr


def test_every_source_has_a_bibtex_entry_also_in_the_book():
    book_bib = (ROOT / "book" / "references.bib").read_text(encoding="utf-8")
    for key in rp.SOURCE_KEYS:
        entry = rp.source_bibtex(key)
        assert entry.startswith("@"), key
        assert entry.strip() in book_bib, f"book/references.bib differs from data/sources.bib for {key}"


def test_every_paper_file_in_the_project_is_valid():
    files = sorted(f for f in (ROOT / "data" / "paper").rglob("*.csv") if f.name != "inventory.csv")
    for f in files:
        p = rp.parse_paper_file(f)
        assert p.provenance["document"] == f.parent.name, f
        rp.validate_id(f.stem)


def test_citation_cff_lists_the_four_documents():
    text = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    assert "cff-version:" in text and "references:" in text
    for doi_or_title in ("10.11918/201811112", "Influence of gravity disturbance", "Improved SINS/ADS",
                         "Error Estimation of Airborne Gravimeter"):
        assert doi_or_title in text


def test_one_repository_address_everywhere():
    """pyproject.toml's ``[project.urls] Repository`` is the address the package reports, and the
    one the README (near the top), CITATION.cff, the book's configuration, the book's ``[source]``
    links, ``cite`` and ``--version`` carry; no other repository address appears.  LICENSE is the
    licence pyproject.toml names."""
    import tomllib

    import yaml

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    url = project["urls"]["Repository"]
    assert url.startswith("https://") and not url.endswith("/") and replication.repository_url() == url
    texts = {name: (ROOT / name).read_text(encoding="utf-8") for name in ("README.md", "CITATION.cff", "book/_config.yml")}
    for name, text in texts.items():
        others = {u for u in re.findall(r"https?://(?:www\.)?github\.com/[^\s\"')>]*", text)
                  if u.rstrip("/.") != url and not u.startswith(url + "/")}
        assert url in text and not others, (name, others)
    assert url in "\n".join(texts["README.md"].splitlines()[:6])
    cff = yaml.safe_load(texts["CITATION.cff"])
    assert cff["repository-code"] == url and cff["url"] == url and cff["date-released"]
    assert cff["license"] == project["license"]["text"] == "MIT" and cff["version"] == replication.__version__
    assert (ROOT / "LICENSE").read_text(encoding="utf-8").startswith("MIT License\n")
    book = yaml.safe_load(texts["book/_config.yml"])
    assert book["repository"]["url"] == url and book["html"]["use_repository_button"] is True
    assert "sphinx.ext.linkcode" in book["sphinx"]["extra_extensions"] and "source_links" in book["sphinx"]["local_extensions"]
    sys.path.insert(0, str(ROOT / "book" / "_ext"))
    try:
        import source_links
    finally:
        sys.path.remove(str(ROOT / "book" / "_ext"))
    link = source_links.source_url({"module": "replication.registry.reading", "fullname": "resolve_table_ids"},
                                   base=url, ref="abc", root=ROOT)
    first, last = (int(n) for n in re.fullmatch(re.escape(url) + r"/blob/abc/replication/registry/reading\.py#L(\d+)-L(\d+)",
                                                link).groups())
    lines = (ROOT / "replication" / "registry" / "reading.py").read_text(encoding="utf-8").splitlines()
    assert lines[first - 1].startswith("def resolve_table_ids(") and lines[last - 1].strip() == "return [ident]"
    assert source_links.source_url({"module": "replication.registry.reproduction", "fullname": "PACKAGE_YEAR"},
                                   base=url, ref="abc", root=ROOT) is None          # data has no source lines
    assert f"url          = {{{url}}}," in rp.bibtex_for("fang2020-table-1")
    version = subprocess.run([sys.executable, "-m", "replication", "--version"], capture_output=True, text=True,
                             check=True).stdout
    assert version.strip() == f"replication {replication.__version__} ({url})"


def test_an_artifact_can_be_covered_by_check_tables(sandbox):
    (sandbox / "data" / "artifacts.csv").write_text(
        "id,source,artifact,description,tables\n"
        "chen2019-eq-4-8,chen2019,Eq. (4-8),closed forms,chen2019-check-a chen2019-check-b\n",
        encoding="utf-8",
    )
    rp.compare("chen2019-check-a", [dict(quantity="q", unit="", paper=1, reproduced=1, tolerance=0)],
               title="A", notebook="book/a.ipynb")
    status, _ = rp.build_index()
    row = status.iloc[0]
    assert row["id"] == "chen2019-eq-4-8" and row["status"] == "reproduced" and row["tables"] == "chen2019-check-a"
    assert len(status) == 1  # the covering table is not listed again as supplementary
    rp.compare("chen2019-check-b", [dict(quantity="q", unit="", paper=1, reproduced=2, tolerance=0, note="misses")],
               title="B", notebook="book/b.ipynb")
    status, _ = rp.build_index()
    assert status.iloc[0]["status"] == "mixed" and status.iloc[0]["rows"] == 2
    assert status.iloc[0]["reproduced"] == 1 and status.iloc[0]["not_reproduced"] == 1


def test_every_id_printed_by_status_resolves_in_show_and_cite():
    """Every id of the stored status (artifact or table) resolves to the tables that cover it; an
    artifact covered by several gives all of them, one BibTeX entry each; load_table refuses it
    naming every table, load_tables returns them all."""
    status = pd.read_csv(rp.tables_dir() / "status.csv", dtype=str, keep_default_na=False)
    for _, r in status.iterrows():
        tables = r["tables"].split()
        for t in tables:
            assert rp.resolve_table_ids(t) == [t] and rp.resolve_table_id(t) == t
            assert rp.bibtex_for(t).startswith(f"@misc{{repro-{t},")
        if not tables:
            continue
        assert rp.resolve_table_ids(r["id"]) == tables
        if len(tables) == 1:
            assert rp.resolve_table_id(r["id"]) == tables[0]
        else:                                     # several (exercised on a sandbox below as well)
            bib = rp.bibtex_for(r["id"])
            assert [m for m in re.findall(r"@misc\{repro-([^,]+),", bib)] == tables
            with pytest.raises(rp.RegistryError, match=f"covered by {len(tables)} tables: {', '.join(tables)};"):
                rp.load_table(r["id"])
            assert list(rp.load_tables(r["id"])) == tables


def test_every_id_the_status_command_prints_works_in_show_and_cite(sandbox, capsys):
    """Run ``status`` on a sandbox holding an artifact covered by one table, one covered by two
    check tables, a supplementary check and a pending artifact; every id it prints is shown and
    cited (each covering table in turn, with a heading), the pending one refused with its reason."""
    (sandbox / "data" / "artifacts.csv").write_text(
        "id,source,artifact,description,tables\n"
        "chen2019-table-9-9,chen2019,Table 9-9,one table,\n"
        "chen2019-eq-4-8,chen2019,Eq. (4-8),two tables,chen2019-check-a chen2019-check-b\n"
        "chen2019-table-9-8,chen2019,Table 9-8,never exported,\n", encoding="utf-8")
    one = [dict(quantity="q", unit="", paper=1, reproduced=1, tolerance=0)]
    for tid in ("chen2019-table-9-9", "chen2019-check-a", "chen2019-check-b", "toolkit-check-own"):
        rp.compare(tid, one, title=f"Title of {tid}", notebook="book/x.ipynb")
    assert cli(["index"]) == 0
    capsys.readouterr()
    assert cli(["status"]) == 0
    printed = sorted(set(re.findall(r"\b(?:chen2019|toolkit)-(?:table|eq|check)-[0-9a-z.-]*[0-9a-z]",
                                    capsys.readouterr().out)))
    assert printed == ["chen2019-check-a", "chen2019-check-b", "chen2019-eq-4-8", "chen2019-table-9-8",
                       "chen2019-table-9-9", "toolkit-check-own"]
    for ident in printed:
        if ident == "chen2019-table-9-8":         # pending: nothing to show or cite yet, and it says so
            for cmd in ("show", "cite"):
                assert cli([cmd, ident]) == 2
                assert "no table has been exported for it yet" in capsys.readouterr().err
            continue
        tables = rp.resolve_table_ids(ident)
        for fmt in ("md", "csv", "tex"):
            assert cli(["show", ident, "--format", fmt]) == 0, (ident, fmt)
            out = capsys.readouterr().out
            heading = {"md": "**Title of ", "tex": "\\caption{Title of "}.get(fmt)
            assert out.count(heading) == len(tables) if fmt != "csv" else "q,,1.0,,1.0," in out
            headings = re.findall(r"^(?:## |# |% )(chen2019-check-[ab]) \((\d) of 2 tables covering chen2019-eq-4-8\)$",
                                  out, flags=re.M)
            assert headings == ([("chen2019-check-a", "1"), ("chen2019-check-b", "2")] if len(tables) > 1 else [])
        assert cli(["cite", ident]) == 0
        bib = capsys.readouterr().out
        assert re.findall(r"@misc\{repro-([^,]+),", bib) == tables
        assert bib.count(f"url          = {{{replication.repository_url()}}}") == len(tables)
        assert bib.count("@techreport{chen2019,") == (0 if ident.startswith("toolkit") else 1)


def test_load_table_refuses_an_artifact_of_several_tables_naming_all(sandbox):
    (sandbox / "data" / "artifacts.csv").write_text(
        "id,source,artifact,description,tables\n"
        "chen2019-eq-4-8,chen2019,Eq. (4-8),two tables,chen2019-check-a chen2019-check-b\n"
        "chen2019-eq-4-9,chen2019,Eq. (4-9),one table,chen2019-check-c\n", encoding="utf-8")
    for tid in ("chen2019-check-a", "chen2019-check-b", "chen2019-check-c"):
        rp.compare(tid, [dict(quantity="q", unit="", paper=1, reproduced=1, tolerance=0)], title=tid,
                   notebook="book/x.ipynb")
    rp.build_index(write=True)
    assert replication.load_table("chen2019-eq-4-9").attrs["id"] == "chen2019-check-c"
    with pytest.raises(rp.RegistryError, match=r"covered by 2 tables: chen2019-check-a, chen2019-check-b; .*"
                                               r"load_tables\('chen2019-eq-4-8'\)"):
        replication.load_table("chen2019-eq-4-8")
    both = replication.load_tables("chen2019-eq-4-8")
    assert list(both) == ["chen2019-check-a", "chen2019-check-b"] and both["chen2019-check-b"]["paper"].dtype.kind == "f"


def test_cite_gives_year_version_and_the_sidecar_commit():
    import json as _json

    tid = "fang2020-table-1"
    meta = _json.loads((rp.tables_dir() / f"{tid}.json").read_text(encoding="utf-8"))
    bib = rp.bibtex_for(tid)
    assert f"year         = {{{rp.PACKAGE_YEAR}}}" in bib and f"version      = {{{meta['library_version']}}}" in bib
    assert meta["git_commit"][:12] in bib and bib.count("fang2020 Table 1") == 1
    assert "related      = {fang2020}" in bib and "@article{fang2020," in bib
    own = rp.bibtex_for("toolkit-check-strapdown-ideal")
    assert "related" not in own and "supplementary check of the package" in own


def test_datapackage_describes_every_exported_csv():
    """tables/datapackage.json (Frictionless tabular data package) lists every CSV with its exact
    header; every field has a description, every numeric column its unit (a count ``1``, a
    comparison's number the row's ``unit`` column); every cell of a ``number`` field parses as a
    number or is empty (missing)."""
    import json as _json

    path = rp.tables_dir() / rp.DATAPACKAGE
    stored = _json.loads(path.read_text(encoding="utf-8"))
    assert stored == _json.loads(_json.dumps(rp.datapackage(), sort_keys=True, ensure_ascii=False))
    names = {r["path"] for r in stored["resources"]}
    assert names == {p.name for p in rp.tables_dir().glob("*.csv")}
    for res in stored["resources"]:
        df = pd.read_csv(rp.tables_dir() / res["path"], dtype=str, keep_default_na=False)
        assert [f["name"] for f in res["schema"]["fields"]] == list(df.columns), res["path"]
        for f in res["schema"]["fields"]:
            assert f.get("description", "").strip(), (res["path"], f["name"], "no description")
            if f["name"] in rp.FIELD_UNITS and "git_commit" in res:      # a comparison's numeric column
                assert f.get("unitField") == "unit" or f.get("unit") == "1", (res["path"], f["name"], "no unit")
            if f["type"] == "integer" and res["name"] == "status":          # the counts
                assert f.get("unit") == "1", (res["path"], f["name"])
            if f["type"] in ("number", "integer"):
                cells = df[f["name"]][df[f["name"]] != ""]
                assert pd.to_numeric(cells, errors="coerce").notna().all(), (res["path"], f["name"])


def test_load_table_gives_typed_columns_and_provenance():
    import replication

    df = replication.load_table("fang2020-table-1")
    assert df["paper"].dtype.kind == "f" and df["reproduced"].dtype.kind == "f"
    assert df.attrs["id"] == "fang2020-table-1" and df.attrs["notebook"].endswith(".ipynb")
    assert len(df.attrs["git_commit"]) == 40
    with pytest.raises(rp.RegistryError, match="no exported table"):
        replication.load_table("fang2020-table-99")


def test_a_paper_file_that_is_not_utf8_is_refused_with_a_message(tmp_path):
    bad = tmp_path / "chen2019-table-9-9.csv"
    bad.write_bytes("# document: chen2019\nquantity,unit,value\n\xb5,m,1\n".encode("latin-1"))
    with pytest.raises(rp.RegistryError, match="not UTF-8"):
        rp.parse_paper_file(bad)


def test_status_bar_widths_and_refusal():
    html = rp.status_bar_html({"reproduced": 3, "analog": 1, "mixed": 0})
    assert 'width:75.00%' in html and 'width:25.00%' in html
    assert "mixed" not in html  # a status with no artifact draws no segment
    assert html.index("reproduced") < html.index("analog")  # the order of ARTIFACT_STATUSES
    with pytest.raises(rp.RegistryError, match="no artifact"):
        rp.status_bar_html({})


def test_findings_box_states_the_reason_of_every_unreproduced_artifact():
    status, _ = rp.build_index(write=False)
    nb = "book/duan2023/01_sins_ads_error_correction.ipynb"
    box = rp._findings_markdown(status, nb)
    assert box.startswith(":::{admonition} Findings of this chapter") and box.rstrip().endswith(":::")
    mine = status[status["notebook"].str.contains(nb, regex=False)]
    for _, r in mine[~mine["status"].isin(["reproduced", "qualitative"])].iterrows():
        name = r["artifact"] if r["kind"] == "paper" else r["id"]
        line = next(l for l in box.splitlines() if f"**{rp.status_label(r)}**" in l and name in l)
        assert " — " in line and not line.endswith("— -")  # a reason is quoted
    assert "more: see the table" not in box and "…" not in box  # every reason in full, none cut
    # the paper artifacts and the package's own checks are counted apart
    assert "**Paper artifacts**" in box and "**Supplementary checks**" in box


def test_part_summary_links_every_artifact_of_its_paper():
    status, _ = rp.build_index(write=False)
    md = rp._paper_summary_markdown(status, "fang2020")
    ids = status.loc[status["source"] == "fang2020", "id"]
    for i in ids:
        assert f"{{doc}}`{i} " in md
    assert "../../tables/fang2020-table-1.csv" in md and "chen2019" not in md


def test_numbers_are_shown_with_the_digits_their_tolerance_supports():
    df = rp.comparison_frame([
        # a count: whole, never 44.0
        dict(quantity="states", unit="", paper=44.0, reproduced=45.0, basis="parts", agrees=False, note="two parts"),
        # a closed form at a relative 1e-12: the CSV keeps 14 digits, a reader sees DISPLAY_DIGITS
        dict(quantity="A", unit="1/s", paper=3.7367302193658e-5, reproduced=3.7367302193658e-5, tolerance=1e-12,
             tolerance_kind="rel"),
        # a tolerance of 0.01: the value to the grid one decade below it
        dict(quantity="x", unit="m", paper=12.3, reproduced=12.3456789, tolerance=0.01),
        # a transcribed paper value is shown as printed, the reproduced value to as many digits
        dict(quantity="g", unit="m/s^2", paper=9.7803253, reproduced=9.78032534, tolerance=1e-6),
    ])
    assert df.loc[0, "paper"] == "44.0" and df.loc[1, "paper"] == "3.7367302193658e-5"   # CSV digits kept
    shown = [[rp.display_cell(r, c) for c in ("paper", "reproduced", "abs_error")] for _, r in df.iterrows()]
    assert shown[0] == ["44", "45", ""]
    assert shown[1] == ["3.73673e-5", "3.73673e-5", "0"]
    assert shown[2] == ["12.3", "12.346", "0.046"]
    assert shown[3] == ["9.7803253", "9.7803253", "0"]
    assert rp.display_number("44.0") == "44" and rp.display_number("") == "" and rp.display_number("n/a") == "n/a"
    assert rp.display_number("0.123456789", 0.001) == "0.123"
    # the exports and a typed table (load_table's floats) show the same
    typed = df.copy()
    for c in rp.NUMERIC_COLUMNS:
        typed[c] = pd.to_numeric(typed[c].replace("", np.nan))
    assert [[rp.display_cell(r, c) for c in ("paper", "reproduced")] for _, r in typed.iterrows()] == \
        [s[:2] for s in shown]
    md = rp._markdown(df, "t")
    assert "| 44 | 45 |" in md and "3.7367302193658" not in md
    assert "3.7367302193658" not in rp._latex(df, "t", "chen2019-table-9")


def test_a_long_corrected_expression_is_set_as_formulas_that_wrap():
    f = rp._formula(r"F22(1,1) = (V_N \tan L - V_U)/(R_N+h); third row [2\omega_{ie}\cos L + 2V_E/(R_N+h),\ 0]")
    assert f == r"$F22(1,1) = (V_N \tan L - V_U)/(R_N+h);$ third row $[2\omega_{ie}\cos L$ $+ 2V_E/(R_N+h),$ $\ 0]$"
    assert rp._formula(r"\sin^2 2L") == r"$\sin^2 2L$"
    assert rp._formula("sin^2 2L, as printed") == "sin^2 2L, as printed"        # no TeX: text
    assert all(not p.endswith("\\") for p in f.split("$"))          # no piece ends in an escaped dollar


def test_agrees_accepts_numpy_booleans():
    from replication.registry import verdicts as vd
    assert vd.parse_agrees(np.True_) is True and vd.parse_agrees(np.bool_(False)) is False
    assert vd.format_agrees(np.float64(1.0) > 0.5) == "yes"
    with pytest.raises(ValueError):
        vd.parse_agrees(np.int64(1))


def test_claim_rows_declare_their_basis():
    from replication.registry import book
    printed = rp.load_paper("chen2019-claim-abstract")
    q = "45-state model validated by the flight experiment"
    r = book.claim_row(printed, q, holds=np.True_, rests_on="chen2019-table-4-44", note="n")
    assert r["basis"] == "claim" and r["agrees"] is True and r["rests_on"] == ["chen2019-table-4-44"]
    assert r["paper"] == printed.value(q) and "status" not in r
    with pytest.raises(ValueError, match="rests_on"):
        book.claim_row(printed, q, holds=True, rests_on=[], note="n")
    with pytest.raises(ValueError, match="boolean"):
        book.claim_row(printed, q, holds="yes", rests_on=["x"], note="n")
    u = book.unstated_claim_row(printed, q, note="the print lacks x")
    assert u["basis"] == "unstated" and "status" not in u


def test_findings_box_gives_one_line_per_artifact_and_marks_the_failing_part():
    from replication.registry import boxes

    # quantities that share a part are grouped; a long list is counted, never cut inside a name
    assert boxes.quantity_names(["height normal", "height direct", "pitch normal", "pitch direct"]) == \
        "height, pitch (normal, direct)"
    assert boxes.quantity_names(["a | U-turn", "b | U-turn", "c"]) == "a, b (U-turn); c"
    long = boxes.quantity_names([f"quantity number {i} of many" for i in range(40)], limit=60)
    assert long.endswith("more") and "…" not in long
    with pytest.raises(ValueError, match="at least one row"):
        boxes.quantity_names([])
    # the reason a note gives: after an "unstated:" label, else its first clause, brackets closed
    assert boxes._clause("simulated flight, 14 runs; unstated: the field size; more") == "unstated: the field size"
    assert boxes._clause("eqs. (4)-(6) tilt the attitude; then more") == "eqs. (4)-(6) tilt the attitude"
    status, _ = rp.build_index(write=False)
    nb = "book/chen2019/06_gravity_compensation_experiment.ipynb"
    box = boxes.findings_box(status, nb)
    mine = status[status["notebook"].str.contains(nb, regex=False)]
    for _, r in mine[mine["status"] == "mixed"].iterrows():
        line = next(l for l in box.splitlines() if r["artifact"] in l and "**mixed" in l)
        for s in ("not-reproduced", "unverifiable", "analog"):   # each failing status names its rows, counted once
            if int(r[s.replace("-", "_")]):
                assert f"— {s}: " in line or f"; {s}: " in line
                assert line.count(f"{int(r[s.replace('-', '_')])} {s}") == 1
    assert box.count("errata and") == mine["kind"].nunique()     # the counts once per kind of artifact
    with pytest.raises(ValueError, match="chapter path"):
        boxes.findings_box(status, "book/chen2019")
