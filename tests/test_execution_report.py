"""The execution report: scripts/run_notebooks.py records each notebook's run outside the tracked
files, and the book's page (book/_ext/execution_report.py) renders the record at build time, or
says that there is none."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "book" / "_ext"))

import execution_report as er  # noqa: E402


def _run_notebooks():
    spec = importlib.util.spec_from_file_location("run_notebooks", ROOT / "scripts" / "run_notebooks.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


RUN = {"seconds": 12.34, "outcome": "ok", "finished": "2026-01-02T03:04:05+00:00", "jobs": 2,
       "machine": {"cpu": "Test CPU @ 2.6GHz", "cores": 2, "system": "Linux 6.1", "python": "3.11.2",
                   "numpy": "1.26.4", "numba": "0.60.0"}}


def test_the_record_is_not_a_tracked_file():
    rn = _run_notebooks()
    assert rn.REPORT == ROOT / er.REPORT
    rel = rn.REPORT.relative_to(ROOT).as_posix()
    r = subprocess.run(["git", "check-ignore", "-q", rel], cwd=ROOT, check=False)
    assert r.returncode == 0, f"{rel} must be git-ignored: running the book must leave git status clean"


def test_runs_are_merged_into_the_record(tmp_path):
    rn = _run_notebooks()
    report = tmp_path / ".cache" / "execution-report.json"
    rn.record_runs({"book/b.ipynb": RUN}, report)
    rn.record_runs({"book/a.ipynb": dict(RUN, seconds=None, outcome="failed")}, report)
    rn.record_runs({"book/b.ipynb": dict(RUN, seconds=3.0)}, report)      # the latest run replaces the earlier
    data = json.loads(report.read_text(encoding="utf-8"))
    assert list(data["notebooks"]) == ["book/a.ipynb", "book/b.ipynb"]
    assert data["notebooks"]["book/b.ipynb"]["seconds"] == 3.0
    m = rn.machine()
    assert m["cores"] >= 1 and m["python"].count(".") == 2 and m["numpy"] and m["cpu"]


def test_rows_and_machines_of_a_record(tmp_path):
    assert er.load_report(tmp_path / "missing.json") is None
    (tmp_path / "bad.json").write_text("{not json", encoding="utf-8")
    assert er.load_report(tmp_path / "bad.json") is None
    other = dict(RUN, machine=dict(RUN["machine"], cpu="Other CPU"))
    machines, rows = er.report_rows({"notebooks": {"book/x/02.ipynb": other, "book/x/01.ipynb": RUN,
                                                   "book/x/03.ipynb": dict(RUN, seconds=None, outcome="failed")}})
    assert machines[0].startswith("Test CPU @ 2.6GHz, 2 cores, Linux 6.1, Python 3.11.2, numpy 1.26.4")
    assert rows[0] == ["book/x/01.ipynb", "12.3 s", "2026-01-02 03:04:05+00:00", "ok", "2", "A"]
    assert rows[1][-1] == "B" and rows[2][1:4] == ["-", "2026-01-02 03:04:05+00:00", "failed"]


def _build(tmp_path, record):
    from sphinx.application import Sphinx

    src = tmp_path / "repo" / "book"
    src.mkdir(parents=True)
    (src / "conf.py").write_text(f"import sys\nsys.path.insert(0, {str(ROOT / 'book' / '_ext')!r})\n"
                                 "extensions = ['execution_report']\n", encoding="utf-8")
    (src / "index.rst").write_text("Report\n======\n\n.. execution-report::\n", encoding="utf-8")
    if record is not None:
        path = tmp_path / "repo" / er.REPORT
        path.parent.mkdir(parents=True)
        path.write_text(json.dumps(record), encoding="utf-8")
    out = tmp_path / "out"
    app = Sphinx(str(src), str(src), str(out), str(tmp_path / "doctrees"), "html", status=None, warning=None,
                 freshenv=True)
    app.build()
    return (out / "index.html").read_text(encoding="utf-8")


def test_the_page_renders_the_record_or_says_there_is_none(tmp_path, monkeypatch):
    monkeypatch.delenv("REPLICATION_ROOT", raising=False)
    html = _build(tmp_path / "none", None)
    assert "No notebook run has been recorded" in html
    html = _build(tmp_path / "one", {"notebooks": {"book/x/01.ipynb": RUN}})
    assert "2.6GHz, 2 cores, Linux 6.1" in html and "12.3 s" in html and "2026-01-02 03:04:05" in html
    assert "No notebook run has been recorded" not in html
