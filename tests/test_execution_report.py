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
    assert rows[0] == ["book/x/01.ipynb", "12.3 s", "2026-01-02 03:04:05", "ok", "2", "A"]
    assert rows[1][-1] == "B" and rows[2][1:4] == ["-", "2026-01-02 03:04:05", "failed"]


def test_a_record_from_another_machine_reads_the_same():
    """The finish in UTC whatever offset the record carries; a run without a time (failed, timed
    out) or with a malformed entry; one core; machines past Z named AA, AB ..."""
    assert er.finished_utc("2026-01-02T05:04:05+02:00") == "2026-01-02 03:04:05"
    assert er.finished_utc("2026-01-01T22:04:05-05:00") == "2026-01-02 03:04:05"
    assert er.finished_utc("2026-01-02T03:04:05") == "2026-01-02 03:04:05"
    assert er.finished_utc(None) == "" and er.finished_utc("yesterday") == "yesterday"
    assert er.run_time(None) == "-" and er.run_time("n/a") == "-" and er.run_time(3599.96) == "3600.0 s"
    one = er.report_rows({"notebooks": {"book/a.ipynb": dict(RUN, machine=dict(RUN["machine"], cores=1))}})[0]
    assert one[0].startswith("Test CPU @ 2.6GHz, 1 core, Linux")
    many = {f"book/m/{i:02d}.ipynb": dict(RUN, machine=dict(RUN["machine"], cpu=f"CPU {i}")) for i in range(28)}
    many["book/m/99.ipynb"] = "not a run"
    machines, rows = er.report_rows({"notebooks": many})
    assert [r[-1] for r in rows[25:]] == ["Z", "AA", "AB", "AC"] and len(machines) == 29
    assert rows[-1][1:5] == ["-", "", "", ""]


def _build(tmp_path, record, confoverrides=None):
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
    from sphinx.util.docutils import docutils_namespace

    with docutils_namespace():   # the build's nodes and directives are forgotten afterwards, as in a new process
        app = Sphinx(str(src), str(src), str(out), str(tmp_path / "doctrees"), "html", status=None, warning=None,
                     freshenv=True, confoverrides=confoverrides or {})
        app.build()
    return (out / "index.html").read_text(encoding="utf-8")


def test_the_page_renders_the_record_or_says_there_is_none(tmp_path, monkeypatch):
    monkeypatch.delenv("REPLICATION_ROOT", raising=False)
    html = _build(tmp_path / "none", None)
    assert "No notebook run has been recorded" in html
    html = _build(tmp_path / "one", {"notebooks": {"book/x/01.ipynb": RUN}})
    assert "2.6GHz, 2 cores, Linux 6.1" in html and '<span class="nowrap">12.3 s</span>' in html
    assert '<span class="nowrap">2026-01-02</span> <span class="nowrap">03:04:05</span>' in html
    assert "book/<wbr>x/<wbr>01<wbr>.ipynb" in html      # a path breaks after '/' and '_', before '.' only
    assert "No notebook run has been recorded" not in html


def test_the_configuration_names_another_record(tmp_path, monkeypatch):
    """``execution_report`` in the Sphinx configuration: that record, not the checkout's."""
    other = tmp_path / "elsewhere.json"
    other.write_text(json.dumps({"notebooks": {"book/y/long_name_of_a_notebook.ipynb": RUN}}), encoding="utf-8")
    monkeypatch.setenv("REPLICATION_ROOT", str(tmp_path / "no-such-checkout"))
    html = _build(tmp_path / "conf", None, confoverrides={"execution_report": str(other)})
    assert "book/<wbr>y/<wbr>long_<wbr>name_<wbr>of_<wbr>a_<wbr>notebook<wbr>.ipynb" in html


def test_the_usable_cpus_not_the_hosts(monkeypatch, tmp_path):
    """The default number of notebooks at once: the CPUs granted to this process (affinity mask,
    cgroup quota rounded up), not the host's count: 16 cores, one, and a quota of 1.5 of 16."""
    rn = _run_notebooks()
    cpu_max = tmp_path / "cpu.max"
    monkeypatch.setattr(rn.os, "cpu_count", lambda: 64)
    monkeypatch.setattr(rn.os, "sched_getaffinity", lambda pid: set(range(16)))
    assert rn.usable_cpus(cpu_max) == 16                      # no cgroup file
    cpu_max.write_text("max 100000\n", encoding="utf-8")
    assert rn.usable_cpus(cpu_max) == 16
    cpu_max.write_text("150000 100000\n", encoding="utf-8")
    assert rn.usable_cpus(cpu_max) == 2
    monkeypatch.setattr(rn.os, "sched_getaffinity", lambda pid: {3})
    assert rn.usable_cpus(cpu_max) == 1
    cpu_max.write_text("garbage\n", encoding="utf-8")
    assert rn.usable_cpus(cpu_max) == 1


def test_a_failed_or_timed_out_run_is_an_outcome(tmp_path):
    """A cell that raises, and one that outlasts the cell timeout (a slow or busy machine): each is
    an outcome of the run without a time (the report shows it), not an exception that stops the
    other notebooks; the notebook is left as it was."""
    import nbformat

    rn = _run_notebooks()
    runs = {}
    # the raising cell has all the time a busy machine may need; the sleeping one outlasts 3 s anywhere
    for name, code, timeout in (("raises", "raise ValueError('no')", 600), ("sleeps", "import time\ntime.sleep(600)", 3)):
        nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(code)])
        path = tmp_path / f"{name}.ipynb"
        nbformat.write(nb, path)
        before = path.read_text(encoding="utf-8")
        runs[name] = rn._run_one(path, timeout=timeout, rms=rn.IMAGE_RMS)[1:3]
        assert path.read_text(encoding="utf-8") == before
    assert runs == {"raises": (None, "failed"), "sleeps": (None, "timeout")}
