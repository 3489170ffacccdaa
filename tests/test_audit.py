"""The planted-status suite: bad statuses planted one at a time in a throw-away copy of the stored
tables, each of which ``python -m replication index`` must refuse with a message naming the table,
the row and the reason (replication/registry/audit.py).

Each plant is made twice where it matters: as a hand edit of a CSV (the digest refuses it) and as
a forgery that also rewrites the sidecar's digest (the status criteria, the derivation from the
declared basis or the verdict rule refuse it).  Rows are chosen by what they are (the first
reproduced row of a table without a ledger, ...), not by name, so the suite follows the tables.
"""

from __future__ import annotations

import functools
import hashlib
import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from replication.registry import audit
from replication.registry import reproduction as rp
from replication.registry import verdicts as vd

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture()
def copy(tmp_path, monkeypatch):
    """A throw-away project root: a copy of tables/ and data/, the book and the tests linked."""
    shutil.copytree(ROOT / "tables", tmp_path / "tables")
    shutil.copytree(ROOT / "data", tmp_path / "data")
    for d in ("book", "tests", "replication"):
        (tmp_path / d).symlink_to(ROOT / d)
    (tmp_path / "pyproject.toml").write_text("", encoding="utf-8")
    monkeypatch.setenv("REPLICATION_ROOT", str(tmp_path))
    return tmp_path


def _problems() -> set[str]:
    return set(map(str, audit.audit()))


@functools.cache
def _pristine() -> frozenset[str]:
    """:func:`_problems` of an untouched copy of the stored tables: every copy is the same until a
    test plants in it, so the audit before the plant is run once for the module (each test takes it
    first thing, before it changes its copy)."""
    return frozenset(_problems())


def _tables(root: Path) -> dict[str, pd.DataFrame]:
    return {tid: rp.read_table(tid) for tid in rp.list_tables()}


def _write(root: Path, tid: str, df: pd.DataFrame, forge: bool) -> None:
    """Write a planted CSV; with ``forge`` also rewrite the sidecar's digest to match it."""
    text = df.to_csv(index=False, lineterminator="\n")
    (root / "tables" / f"{tid}.csv").write_text(text, encoding="utf-8")
    if forge:
        side = root / "tables" / f"{tid}.json"
        meta = json.loads(side.read_text(encoding="utf-8"))
        meta["table_digest"] = hashlib.sha256(text.encode()).hexdigest()
        side.write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n", encoding="utf-8")


def _refused(before: set[str], tid: str, quantity: str | None, *words: str) -> None:
    new = _problems() - before
    hits = [p for p in new if p.startswith(f"{tid}:") and (quantity is None or repr(quantity) in p)
            and all(w in p for w in words)]
    assert hits, f"plant in {tid} row {quantity!r} not refused with {words}; new problems: {sorted(new)[:5]}"


def _is_ledger(tid: str) -> bool:
    return tid.endswith("-readings")


def _pick(tables, pred):
    for tid, df in tables.items():
        for i, r in df.iterrows():
            if pred(tid, r):
                return tid, i, df.copy()
    pytest.skip("no row of that kind in the stored tables")


def _has_ledger(tid: str) -> bool:
    return bool(rp.readings_ledgers(tid))


# ------------------------------------------------------------------ plants in the stored tables

@pytest.mark.parametrize("forge", [False, True])
def test_a_status_flipped_in_a_table_without_a_ledger(copy, forge):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: not _is_ledger(t) and not _has_ledger(t)
                       and r["status"] == "reproduced")
    df.loc[i, "status"] = "not-reproduced"
    df.loc[i, "note"] = "planted"
    _write(copy, tid, df, forge)
    _refused(before, tid, None if not forge else df.loc[i, "quantity"],
             *(("table_digest",) if not forge else ("within the stated tolerance",)))


def test_a_reproduced_row_far_outside_its_tolerance(copy):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: r["status"] == "reproduced" and r["tolerance"] not in ("", "0")
                       and r["paper"] != "")
    p, tol = float(df.loc[i, "paper"]), float(df.loc[i, "tolerance"])
    scale = abs(p) if df.loc[i, "tolerance_kind"] == "rel" else 1.0
    df.loc[i, "reproduced"] = repr(p + 100 * tol * max(scale, 1e-300))
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"], "reproduced needs")


def test_a_reproduced_row_without_a_tolerance(copy):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: r["status"] == "reproduced")
    df.loc[i, ["tolerance", "tolerance_kind"]] = ""
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"], "reproduced needs")


@pytest.mark.parametrize("label", ["qualitative", "reproduced", "analog"])
def test_a_failure_relabelled(copy, label):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: not _is_ledger(t) and r["status"] == "not-reproduced"
                       and r["tolerance"] != "")
    df.loc[i, "status"] = label
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"])


def test_a_failure_relabelled_unverifiable_where_no_reading_reaches_the_print(copy):
    before = _pristine()
    tables = _tables(copy)

    def pred(t, r):
        if _is_ledger(t) or r["status"] != "not-reproduced" or not _has_ledger(t):
            return False
        meta = rp._sidecar(t)
        ev = audit.ledger_evidence(r["quantity"], tables[t], meta, audit._ledger_rows(rp.readings_ledgers(t, meta)))
        return not ev.reaching

    tid, i, df = _pick(tables, pred)
    df.loc[i, "status"] = "unverifiable"
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"])


def test_an_inconsistency_relabelled_erratum(copy):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: r["status"] == "inconsistent" and r["evidence"] == "")
    df.loc[i, "status"] = "erratum"
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"], "erratum")


def test_an_erratum_with_evidence_that_does_not_exist(copy):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: r["status"] == "erratum")
    df.loc[i, "evidence"] = "tests/test_nowhere.py::test_never_written"
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"], "evidence")


def test_a_declared_basis_contradicted_by_the_stored_status(copy):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: r.get("basis", "") == "value" and r["status"] == "reproduced")
    df.loc[i, "status"] = "qualitative"
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"])


def test_a_pending_row_and_an_unknown_status(copy):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: r["status"] == "qualitative")
    df.loc[i, "status"] = "pending"
    j = next(k for k in df.index if k != i)
    df.loc[j, "status"] = "reproduced-ish"
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"], "pending")
    _refused(before, tid, df.loc[j, "quantity"], "unknown status")


def test_an_analog_row_with_error_columns(copy):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: r["status"] == "analog")
    df.loc[i, ["abs_error", "rel_error"]] = ["0.1", "0.01"]
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"], "error columns")


def test_a_note_removed(copy):
    before = _pristine()
    tid, i, df = _pick(_tables(copy), lambda t, r: not _is_ledger(t) and r["status"] == "unverifiable")
    df.loc[i, "note"] = ""
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"], "note")


def _ledgered_table(copy) -> tuple[str, dict, str]:
    for tid in rp.list_tables():
        meta = rp._sidecar(tid)
        if not _is_ledger(tid) and meta.get("main_reading") and rp.readings_ledgers(tid, meta):
            return tid, meta, rp.readings_ledgers(tid, meta)[0]
    pytest.skip("no table with a readings ledger")


def test_a_ledger_deleted(copy):
    before = _pristine()
    tid, meta, lid = _ledgered_table(copy)
    (copy / "tables" / f"{lid}.csv").unlink()
    (copy / "tables" / f"{lid}.json").unlink()
    _refused(before, tid, None, "ledger")


def test_a_reading_renamed_with_the_diagnostic_prefix(copy):
    """The reading that ruled_out names, renamed 'diagnostic: …' in the ledger (digest forged):
    the ruled_out entry then names no reading, and the renamed reading still reaches the print."""
    before = _pristine()
    for tid in rp.list_tables():
        meta = rp._sidecar(tid)
        if meta.get("ruled_out") and rp.readings_ledgers(tid, meta):
            break
    else:
        pytest.skip("no ruled-out reading")
    key = next(iter(meta["ruled_out"]))
    lid = rp.readings_ledgers(tid, meta)[0]
    df = rp.read_table(lid)
    df["quantity"] = [q.replace(key, f"diagnostic: {key}", 1) if q.startswith(key) else q for q in df["quantity"]]
    _write(copy, lid, df, True)
    _refused(before, tid, None)


def test_a_ruled_out_reading_with_meaningless_evidence(copy):
    before = _pristine()
    for tid in rp.list_tables():
        meta = rp._sidecar(tid)
        if meta.get("ruled_out"):
            break
    else:
        pytest.skip("no ruled-out reading")
    key = next(iter(meta["ruled_out"]))
    meta["ruled_out"][key] = "it seemed unlikely to us"
    (copy / "tables" / f"{tid}.json").write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    _refused(before, tid, None, "quotes no printed value")


def test_a_main_reading_ledger_row_flipped(copy):
    before = _pristine()
    for tid in rp.list_tables():
        meta = rp._sidecar(tid)
        if _is_ledger(tid) or not meta.get("main_reading") or not rp.readings_ledgers(tid, meta):
            continue
        lid = rp.readings_ledgers(tid, meta)[0]
        df, main = rp.read_table(lid), rp.read_table(tid).set_index("quantity")["status"]
        prefix = meta["main_reading"] + rp.READING_SEPARATOR
        idx = [i for i, q in enumerate(df["quantity"]) if q.startswith(prefix)
               and main.get(q[len(prefix):]) == df.loc[i, "status"]]
        if idx:
            break
    else:
        pytest.skip("no main reading in its ledger")
    i = idx[0]
    df.loc[i, "status"] = "not-reproduced" if df.loc[i, "status"] != "not-reproduced" else "qualitative"
    _write(copy, lid, df, True)
    _refused(before, tid, df.loc[i, "quantity"][len(prefix):], "main reading")


def test_a_stray_csv_without_a_sidecar(copy):
    before = _pristine()
    src = next(iter(rp.list_tables()))
    shutil.copy(copy / "tables" / f"{src}.csv", copy / "tables" / "chen2019-table-99-9.csv")
    _refused(before, "chen2019-table-99-9", None, "sidecar")


def test_index_refuses_a_plant_on_the_command_line(copy):
    """What a user runs: ``python -m replication index`` exits 2 and names table, row and reason."""
    import subprocess
    import sys

    tid, i, df = _pick(_tables(copy), lambda t, r: r["status"] == "reproduced" and r["paper"] != ""
                       and r["tolerance"] not in ("", "0"))
    df.loc[i, "reproduced"] = repr(float(df.loc[i, "paper"]) + 1e6 * (1 + abs(float(df.loc[i, "paper"]))))
    _write(copy, tid, df, True)
    r = subprocess.run([sys.executable, "-m", "replication", "index"], cwd=copy, capture_output=True, text=True,
                       env={**__import__("os").environ, "REPLICATION_ROOT": str(copy)})
    assert r.returncode != 0
    assert tid in r.stderr + r.stdout and repr(df.loc[i, "quantity"]) in r.stderr + r.stdout


# ------------------------------------------------------------------ the derivation itself

@pytest.mark.parametrize("ev, status", [
    (vd.Evidence("value", within=True), "reproduced"),
    (vd.Evidence("value", within=False), "not-reproduced"),
    (vd.Evidence("value", within=False, ledger=vd.LedgerEvidence(("r",), ("r",), True)), "unverifiable"),
    (vd.Evidence("value", within=False, ledger=vd.LedgerEvidence(("r",), (), True)), "inconsistent"),
    (vd.Evidence("verdict", agrees=True), "qualitative"),
    (vd.Evidence("verdict", agrees=False), "not-reproduced"),
    (vd.Evidence("verdict", agrees=False, ledger=vd.LedgerEvidence(("r",), ("r",), True)), "unverifiable"),
    (vd.Evidence("parts", agrees=False), "inconsistent"),
    (vd.Evidence("parts", agrees=True), "qualitative"),
    (vd.Evidence("derivation", agrees=False), "erratum"),
    (vd.Evidence("derivation", agrees=False, ledger=vd.LedgerEvidence(("r",), ("r",), False)), "inconsistent"),
    (vd.Evidence("derivation", within=True), "reproduced"),
    (vd.Evidence("claim", agrees=True, rests_on=("reproduced", "qualitative")), "qualitative"),
    (vd.Evidence("claim", agrees=True, rests_on=("reproduced", "not-reproduced")), "not-reproduced"),
    (vd.Evidence("claim", agrees=True, rests_on=("analog", "unverifiable")), "unverifiable"),
    (vd.Evidence("claim", agrees=True, rests_on=("analog", "qualitative")), "analog"),
    (vd.Evidence("claim", agrees=False, rests_on=("reproduced",)), "inconsistent"),
    (vd.Evidence("stand-in", agrees=True), "analog"),
    (vd.Evidence("stand-in", agrees=False), "not-reproduced"),
    (vd.Evidence("unstated"), "unverifiable"),
])
def test_the_status_follows_from_the_evidence(ev, status):
    assert vd.derive_status(ev) == status


@pytest.mark.parametrize("ev, words", [
    (vd.Evidence("guess"), "unknown basis"),
    (vd.Evidence("value"), "tolerance"),
    (vd.Evidence("claim", agrees=True), "rests_on"),
    (vd.Evidence("verdict"), "agrees"),
])
def test_missing_evidence_is_refused(ev, words):
    with pytest.raises(ValueError, match=words):
        vd.derive_status(ev)


def test_a_ruled_out_sentence_must_quote_a_printed_value():
    printed = [36.5872, 1.845e-18, 0.004781]
    assert audit.quotes_printed_value("δA_xz = 36.59 is observable", printed)
    assert audit.quotes_printed_value("round-off (1.8e-18)", printed)
    assert not audit.quotes_printed_value("it seemed unlikely", printed)
    assert not audit.quotes_printed_value("1 of 3 readings", printed)      # one digit proves nothing
    assert not audit.quotes_printed_value("36.60 is observable", printed)


def test_the_stored_tables_pass_the_audit():
    """Every stored table of the project: no problem (what `python -m replication index` checks)."""
    problems = audit.audit()
    assert not problems, "\n".join(map(str, problems[:20]))


# ------------------------------------------------------------------ plants found by an independent tester

def test_a_printed_value_edited_in_the_table(copy):
    """The paper column is the paper file's: a 'printed' value changed to meet the reproduction is refused."""
    before = _pristine()

    def pred(t, r):
        src = rp._sidecar(t).get("paper_source")
        if not src or r["paper"] == "" or r["reproduced"] == "" or r["status"] != "erratum":
            return False
        vals = rp.parse_paper_file(rp.data_root() / src).numeric()
        return r["quantity"] in vals.index and vals[r["quantity"]] == vals[r["quantity"]] and \
            float(r["reproduced"]) != vals[r["quantity"]]

    tid, i, df = _pick(_tables(copy), pred)
    df.loc[i, "paper"] = df.loc[i, "reproduced"]
    df.loc[i, ["abs_error", "rel_error"]] = ["0", "0"]
    df.loc[i, "status"] = "reproduced"
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"], "is not the printed")


def test_a_failure_redeclared_unstated_where_the_ledger_tries_it(copy):
    before = _pristine()
    tables = _tables(copy)

    def pred(t, r):
        if _is_ledger(t) or r["status"] != "not-reproduced" or not _has_ledger(t):
            return False
        rows = audit._ledger_rows(rp.readings_ledgers(t))
        return any(r["quantity"] in per for per in rows.values())

    tid, i, df = _pick(tables, pred)
    df.loc[i, ["basis", "status", "tolerance", "tolerance_kind", "abs_error", "rel_error"]] = \
        ["unstated", "unverifiable", "", "", "", ""]
    _write(copy, tid, df, True)
    _refused(before, tid, df.loc[i, "quantity"], "no reading reaches")


def test_the_main_reading_renamed_away_from_its_ledger_rows(copy):
    """A main reading renamed so that its ledger rows are no longer compared with the main rows: the
    reading whose results are the main table's must be the one named."""
    before = _pristine()
    for tid in rp.list_tables():
        meta = rp._sidecar(tid)
        if _is_ledger(tid) or not meta.get("main_reading") or not rp.readings_ledgers(tid, meta):
            continue
        rows = audit._ledger_rows(rp.readings_ledgers(tid, meta))
        main = rp.read_table(tid)
        per = rows.get(meta["main_reading"], {})
        vals = {r["quantity"]: (r["reproduced"], r["reproduced_text"]) for _, r in main.iterrows()}
        shared = [q for q in per if q in vals]
        if len(shared) >= 5 and all((per[q]["reproduced"], per[q]["reproduced_text"]) == vals[q] for q in shared):
            break
    else:
        pytest.skip("no ledger holding its main reading with the main table's results")
    meta["main_reading"] = meta["main_reading"] + " (renamed)"
    (copy / "tables" / f"{tid}.json").write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    _refused(before, tid, None, "name it as the main reading")


def test_the_sidecar_counts_follow_the_csv(copy):
    before = _pristine()
    tid = next(t for t in rp.list_tables() if not _is_ledger(t))
    side = copy / "tables" / f"{tid}.json"
    meta = json.loads(side.read_text(encoding="utf-8"))
    meta["status_counts"] = dict(meta["status_counts"], reproduced=meta["status_counts"].get("reproduced", 0) + 7)
    side.write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    _refused(before, tid, None, "status_counts")


def test_reading_outcomes_says_what_each_reading_alone_gives_a_row():
    """Each reading of a stored ledger, alone, by the registry's rule: a reading that reaches the print
    and keeps its group gives unverifiable, one that reaches nothing not-reproduced; the row's stored
    status is the one the whole ledger gives."""
    tid, q = "duan2023-table-1", "SINS / misalignment"
    out = audit.reading_outcomes(tid, q)
    assert list(out.columns) == ["reading", "counted", "reaches", "keeps_group", "status"]
    assert set(out["status"]) <= {"not-reproduced", "unverifiable", "inconsistent"}
    assert (out.loc[~out["reaches"], "status"] == "not-reproduced").all()
    assert (out.loc[out["reaches"] & out["keeps_group"], "status"] == "unverifiable").all()
    stored = rp.read_table(tid).set_index("quantity").loc[q, "status"]
    whole = vd.after_ledger(vd.LedgerEvidence(tuple(out.loc[out["reaches"], "reading"]),
                                              tuple(out.loc[out["keeps_group"], "reading"]), True), "not-reproduced")
    assert stored == whole
    with pytest.raises(rp.RegistryError, match="no row"):
        audit.reading_outcomes(tid, "no such row")


def test_the_csv_parse_refuses_text_in_place_of_bytes():
    from replication.registry.reading import csv_text_frame

    assert list(csv_text_frame(b"a,b\n1,\n")["b"]) == [""]
    with pytest.raises(TypeError, match="content must be the file's bytes"):
        csv_text_frame("a,b\n1,2\n")
