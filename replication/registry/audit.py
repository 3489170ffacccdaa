"""The audit of the stored tables: every row of every table re-judged on every ``index``.

``python -m replication index`` (run by ``make book`` and ``make test``) refuses the tables when
any of these fails (CONTRIBUTING.md, "Statuses" and "Readings and the main reading"):

1. **Stored is computed.** Each ``tables/<id>.csv`` has its sidecar and matches the sidecar's
   ``table_digest``: a hand edit of a CSV is refused.
2. **A declared basis decides the status.** A row that names its ``basis`` carries the status
   :func:`replication.registry.verdicts.derive_status` gives for its stored evidence.
3. **Each status meets its criteria**, for every row whether or not it names a basis (the
   criteria a program can check, listed in :data:`CRITERIA`).
4. **Ledgers are there and say what the main table says.** A ledger a sidecar names exists; the
   main reading's ledger row carries its main row's status; a ``ruled_out`` entry quotes a printed
   value that ``data/paper/`` holds; a ``not-reproduced`` or ``erratum`` row stands beside no
   reading that reaches the print unless that reading is ruled out — whatever the reading's name
   (a ``diagnostic`` prefix switches nothing off).

Each problem names the table, the row and the reason.
"""

from __future__ import annotations

import functools
import hashlib
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Mapping

import pandas as pd

from replication.registry import reproduction as rp
from replication.registry import verdicts as vd
from replication.registry.reading import csv_text_frame

CRITERIA = {
    "reproduced": "numbers and a tolerance, the stored error within it",
    "not-reproduced": "a note; something printed compared (paper or paper_text); outside the tolerance when one "
                      "is given; in a main table, a readings ledger or a tolerance that decides it; no reading "
                      "of the ledger reaching the print unless ruled out by printed evidence",
    "erratum": "a note; evidence naming a notebook and a test that exist; the printed value outside the "
               "tolerance when one is given; no reading of the ledger reaching the print",
    "inconsistent": "a note saying which printed part says what; something printed compared",
    "qualitative": "a note; no tolerance (a row compared against a tolerance is reproduced or not by its "
                   "numbers)",
    "analog": "a note; no error columns and no tolerance (a stand-in is not compared number for number)",
    "unverifiable": "a note naming what the print lacks; no tolerance that the stored numbers meet",
    "pending": "never in a stored table",
}
"""What each status needs and what forbids it, as the audit checks it (CONTRIBUTING.md, "Statuses")."""


@dataclass(frozen=True)
class Problem:
    """One refusal of the audit.

    Attributes
    ----------
    table : str
        The table (or ``inventory of <key>``).
    row : str
        The row's quantity; empty for the table as a whole.
    reason : str
        Why, in words a chapter's author can act on.
    """

    table: str
    row: str
    reason: str

    def __str__(self) -> str:
        return f"{self.table}: row {self.row!r}: {self.reason}" if self.row else f"{self.table}: {self.reason}"


_NUM_RE = re.compile(r"(?<![\w.])[-−]?\d+(?:\.\d+)?(?:\s*[eE]\s*[-−+]?\d+)?(?![\w.])")


def _num(v: Any) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return float("nan")
    return f


def _within(row: Mapping[str, Any]) -> bool | None:
    """Whether the stored numbers of a row lie within its stored tolerance (None when not compared)."""
    p, r, tol = _num(row["paper"]), _num(row["reproduced"]), _num(row["tolerance"])
    if any(math.isnan(x) for x in (p, r, tol)):
        return None
    err = abs(r - p)
    if row["tolerance_kind"] == "rel":
        err = err / abs(p) if p else (0.0 if err == 0 else math.inf)
    # the registry stores the error on the tolerance's grid; allow its last-digit rounding
    return err <= tol * (1 + 1e-9) + 1e-300


def _printed_numbers(text: str) -> list[str]:
    return [m.group(0).replace("−", "-").replace(" ", "") for m in _NUM_RE.finditer(str(text))]


def _sig(token: str) -> int:
    mant = token.lstrip("-").split("e")[0].split("E")[0].replace(".", "").lstrip("0")
    return len(mant)


def quotes_printed_value(text: str, printed: Iterable[float]) -> bool:
    """Whether ``text`` quotes one of the ``printed`` values: a number of at least two significant
    digits in the text that equals a printed value rounded to as many digits.

    Parameters
    ----------
    text : str
        The evidence sentence.
    printed : iterable of float
        The values the paper files hold.

    Returns
    -------
    bool
    """
    vals = [v for v in printed if math.isfinite(v) and v != 0]
    for tok in _printed_numbers(text):
        n = _sig(tok)
        if n < 2:
            continue
        try:
            t = float(tok)
        except ValueError:
            continue
        for v in vals:
            if rp.round_sig(v, n) == rp.round_sig(t, n):
                return True
    return False


def _paper_values(meta: Mapping[str, Any], table_id: str) -> list[float]:
    """Every number of the table's paper file, else of every paper file of its source."""
    root = rp.data_root()
    files = [root / meta["paper_source"]] if meta.get("paper_source") else []
    if not files or not files[0].exists():
        files = sorted(f for f in (rp.paper_dir() / table_id.split("-", 1)[0]).glob("*.csv") if f.name != "inventory.csv")
    out = []
    for f in files:
        for line in f.read_text(encoding="utf-8").splitlines():
            if not line.startswith("#"):
                out += [_num(t) for t in _printed_numbers(line)]
    return [v for v in out if not math.isnan(v)]


def _test_exists(root: Path, ref: str) -> bool:
    path, _, name = ref.partition("::")
    p = root / path.strip()
    if not p.is_file():
        return False
    name = name.strip().split("[")[0]
    return not name or re.search(rf"^\s*(async\s+)?def {re.escape(name)}\b", _text_at(str(p), p.stat().st_mtime_ns),
                                 re.M) is not None


def evidence_ok(root: Path, evidence: str, notebook: str = "") -> bool:
    """Whether an ``evidence`` cell names a test that exists (``tests/<file>.py::<name>``) and a
    notebook (or module) that exists — the table's own ``notebook`` when the cell names none.

    Parameters
    ----------
    root : pathlib.Path
        The project root.
    evidence : str
        The cell, items separated by ``;``.
    notebook : str, optional
        The table's notebook (its sidecar's), relative to the root.

    Returns
    -------
    bool
    """
    if not (root / "tests").is_dir():
        return True   # an installed copy ships the tables, not the tests: a clone's index checked them
    items = [t.strip() for t in str(evidence).split(";") if t.strip()]
    tests = [t for t in items if t.startswith("tests/")]
    others = [t for t in items if not t.startswith("tests/")]
    files = [t.split()[0].split("::")[0] for t in others]
    if not files and notebook:
        files = [notebook]
    return bool(tests) and all(_test_exists(root, t) for t in tests) and \
        any((root / f).exists() for f in files)


@functools.lru_cache(maxsize=4096)
def _evidence_ok_once(root: Path, evidence: str, notebook: str = "") -> bool:
    """:func:`evidence_ok` once per cell and table within one :func:`audit_table` (a ledger repeats
    the same evidence on thousands of rows); emptied when each table's audit starts, so a file
    removed between two audits is seen."""
    return evidence_ok(root, evidence, notebook)


@functools.lru_cache(maxsize=1024)
def _records_of(content: bytes) -> tuple[dict, ...]:
    return tuple(csv_text_frame(content).to_dict("records"))


def _records(table_id: str) -> tuple[dict, ...]:
    """The rows of a stored table as dictionaries, made once per content of the file."""
    return _records_of((rp.tables_dir() / f"{table_id}.csv").read_bytes())


@functools.lru_cache(maxsize=256)
def _text_at(path: str, mtime_ns: int) -> str:
    return Path(path).read_text(encoding="utf-8")


def _is_ledger(table_id: str) -> bool:
    return "-check-" in table_id and table_id.endswith("-readings")


def _reaches(ledger_row: Mapping[str, Any], main_row: Mapping[str, Any]) -> bool:
    """Whether a ledger row reaches the printed value of its main row: a row that itself compares
    the print (paper or paper_text) and reaches it by its status, or a number within the main
    row's tolerance of the print.  A row that compares nothing printed reaches nothing by its
    status, whatever its name."""
    if ledger_row["status"] in vd.REACHING and (ledger_row["paper"] != "" or ledger_row["paper_text"] != ""):
        return True
    return bool(_within({"paper": main_row["paper"], "reproduced": ledger_row["reproduced"],
                        "tolerance": main_row["tolerance"], "tolerance_kind": main_row["tolerance_kind"]}))


def _ledger_rows(ledger_ids: list[str]) -> dict[str, dict[str, Mapping[str, Any]]]:
    """``{reading: {quantity: ledger row}}`` over the given ledgers."""
    rows: dict[str, dict[str, Mapping[str, Any]]] = {}
    for lid in ledger_ids:
        if not (rp.tables_dir() / f"{lid}.csv").exists():
            continue
        for lr in _records(lid):
            q = lr["quantity"]
            if rp.READING_SEPARATOR not in q:
                continue
            reading, rest = q.split(rp.READING_SEPARATOR, 1)
            rows.setdefault(reading, {})[rest] = lr
    return rows


def _excluded(reading: str, ruled: Mapping[str, str]) -> bool:
    return any(reading == k or reading.startswith(k) for k in ruled)


def ledger_evidence(q: str, main: pd.DataFrame, meta: Mapping[str, Any],
                    readings: Mapping[str, Mapping[str, Mapping[str, Any]]],
                    by_q: Mapping[str, Mapping[str, Any]] | None = None) -> vd.LedgerEvidence:
    """What the ledger says about the failing row ``q`` of a main table (see
    :class:`replication.registry.verdicts.LedgerEvidence`).

    Parameters
    ----------
    q : str
        The row's quantity.
    main : pandas.DataFrame
        The main table.
    meta : mapping
        Its sidecar (``main_reading``, ``ruled_out``, ``groups``).
    readings : mapping
        ``{reading: {quantity: ledger row}}``.
    by_q : mapping, optional
        The main table's rows by quantity, when already built.

    Returns
    -------
    LedgerEvidence
    """
    if by_q is None:
        by_q = {r["quantity"]: r for r in main.to_dict("records")}
    ruled = dict(meta.get("ruled_out") or {})
    main_reading = meta.get("main_reading", "")
    groups = {k: list(v) for k, v in dict(meta.get("groups") or {}).items()}
    mine = [g for g in groups.values() if q in g]
    reaching, keeping = [], []
    for reading, per_q in readings.items():
        if reading == main_reading or _excluded(reading, ruled) or q not in per_q:
            continue
        if not _reaches(per_q[q], by_q[q]):
            continue
        reaching.append(reading)
        others = [o for g in mine for o in g if o != q and o in by_q and by_q[o]["status"] in vd.REACHING]
        if all(o in per_q and _reaches(per_q[o], by_q[o]) for o in others):
            keeping.append(reading)
    return vd.LedgerEvidence(tuple(reaching), tuple(keeping), bool(mine))


def reading_outcomes(table_id: str, quantity: str) -> pd.DataFrame:
    """What each reading of a table's readings ledger, taken alone, says about one row of the table,
    by the rule of :func:`ledger_evidence` and :func:`replication.registry.verdicts.after_ledger`.

    A chapter shows with it why a row is ``unverifiable`` or ``inconsistent``: which readings reach
    the print, which of them keep the rest of the row's group (the other rows of the group that the
    main reading reaches), and the status each would give the row were it the only reading.

    Parameters
    ----------
    table_id : str
        An exported main table with a readings ledger.
    quantity : str
        One of its rows.

    Returns
    -------
    table : pandas.DataFrame
        One line per reading that shows the row (in the ledger's order): ``reading``, ``counted``
        (False for the main reading and a reading ruled out by printed evidence), ``reaches``,
        ``keeps_group``, ``status`` (what the reading alone gives a row that misses the print under the
        main reading: ``not-reproduced``, ``unverifiable`` or ``inconsistent``).

    Raises
    ------
    RegistryError
        If the table is not exported, has no readings ledger, or has no row ``quantity``.
    """
    if not (rp.tables_dir() / f"{table_id}.csv").exists():
        raise rp.RegistryError(f"{table_id} is not exported")
    meta = rp._sidecar(table_id)
    main = rp.read_table(table_id)
    if quantity not in set(main["quantity"]):
        raise rp.RegistryError(f"{table_id} has no row {quantity!r}")
    ledgers = rp.readings_ledgers(table_id, meta)
    if not ledgers:
        raise rp.RegistryError(f"{table_id} has no readings ledger")
    ruled = dict(meta.get("ruled_out") or {})
    rows = []
    for reading, per_q in _ledger_rows(ledgers).items():
        if quantity not in per_q:
            continue
        ev = ledger_evidence(quantity, main, meta, {reading: per_q})
        counted = reading != meta.get("main_reading", "") and not _excluded(reading, ruled)
        rows.append({"reading": reading, "counted": counted, "reaches": bool(ev.reaching),
                     "keeps_group": bool(ev.keeping_group), "status": vd.after_ledger(ev, "not-reproduced")})
    return pd.DataFrame(rows, columns=["reading", "counted", "reaches", "keeps_group", "status"])


def _row_problems(tid: str, r: Mapping[str, Any], root: Path, ledger: bool, has_ledger: bool,
                  notebook: str = "") -> list[str]:
    """The status criteria (:data:`CRITERIA`) that a stored row breaks."""
    s, note = r["status"], str(r["note"]).strip()
    out = []
    within = _within(r)
    printed = r["paper"] != "" or r["paper_text"] != ""
    if s not in rp.STATUSES:
        return [f"unknown status {s!r}"]
    if s == "pending":
        out.append("a stored table holds no pending row")
    if s == "reproduced" and within is not True:
        out.append("reproduced needs numbers and a tolerance with the stored error within it"
                   + ("" if within is None else f" (error {abs(_num(r['reproduced']) - _num(r['paper'])):.3g} "
                      f"against {r['tolerance']} {r['tolerance_kind']})"))
    if s not in ("reproduced",) and within is True and s not in ("erratum",):
        out.append(f"{s} although the stored numbers lie within the stated tolerance: the numbers make it reproduced")
    if s in ("qualitative", "analog") and r["tolerance"] != "":
        out.append(f"{s} with a tolerance: a row compared against a tolerance is judged by its numbers")
    if s == "analog" and (r["abs_error"] != "" or r["rel_error"] != ""):
        out.append("analog rows carry no error columns (a stand-in is not compared number for number)")
    if s != "reproduced" and not ledger and not note:
        out.append(f"{s} needs a note saying why")
    if s in ("not-reproduced", "inconsistent", "erratum") and not ledger and not printed:
        out.append(f"{s} compares nothing printed (no paper value or printed text)")
    if s == "not-reproduced" and not ledger and within is None and not has_ledger and r.get("basis", "") == "":
        out.append("not-reproduced with neither a tolerance nor a readings ledger: say what decides it "
                   "(a tolerance stated before comparing, or the ledger of the readings tried)")
    if s == "erratum":
        if within is True:
            out.append("an erratum whose printed value lies within the tolerance is not wrong")
        if not _evidence_ok_once(root, r["evidence"], notebook):
            out.append(f"an erratum needs evidence naming a notebook and a test that exist, not {r['evidence']!r}")
    return out


def audit_table(tid: str, meta: Mapping[str, Any] | None = None) -> list[Problem]:
    """Every problem of one stored table (see the module docstring).

    Parameters
    ----------
    tid : str
        An exported table id.
    meta : mapping, optional
        Its sidecar, when already read.

    Returns
    -------
    list of Problem
    """
    root, d = rp.data_root(), rp.tables_dir()
    _evidence_ok_once.cache_clear()
    meta = rp._sidecar(tid) if meta is None else meta
    csv = d / f"{tid}.csv"
    if not csv.exists():
        return [Problem(tid, "", "its sidecar has no CSV")]
    out = []
    changed = rp._digest_problem(tid, meta)
    if changed:
        out.append(Problem(tid, "", changed))
    df = rp.read_table(tid)
    records = _records(tid)
    by_q = {r["quantity"]: r for r in records}
    ledger = _is_ledger(tid)
    named = list(meta.get("readings") or [])
    for lid in named:
        if not (d / f"{lid}.csv").exists() or not (d / f"{lid}.json").exists():
            out.append(Problem(tid, "", f"its sidecar names the readings ledger {lid}, which is not exported"))
    ledgers = rp.readings_ledgers(tid, meta) if not ledger else []
    readings = _ledger_rows(ledgers)
    ruled = dict(meta.get("ruled_out") or {})
    if ruled:
        values = _paper_values(meta, tid)
        for k, ev in ruled.items():
            if not quotes_printed_value(ev, values):
                out.append(Problem(tid, "", f"ruled_out {k!r}: its evidence quotes no printed value that data/paper "
                                            "holds (name the printed numbers that exclude the reading)"))
            if not any(r == k or r.startswith(k) for r in readings):
                out.append(Problem(tid, "", f"ruled_out names {k!r}, which is no reading of {', '.join(ledgers) or 'a ledger'}"))
    counts = {k: int((df["status"] == k).sum()) for k in rp.STATUSES}
    if meta.get("status_counts") not in (None, counts):
        out.append(Problem(tid, "", f"the sidecar's status_counts {meta.get('status_counts')} are not the CSV's {counts}"))
    out += _paper_problems(tid, df, meta)
    main_reading = meta.get("main_reading", "")
    if main_reading and ledgers and readings and main_reading not in readings:
        # a ledger may leave the main reading out (the main table is its result); then no reading of the
        # ledger may be the main computation under another name
        main_values = {r["quantity"]: (r["reproduced"], r["reproduced_text"]) for r in records}
        for reading, per_q in readings.items():
            shared = [q for q in per_q if q in main_values]
            if len(shared) >= 5 and all((per_q[q]["reproduced"], per_q[q]["reproduced_text"]) == main_values[q]
                                        for q in shared):
                out.append(Problem(tid, "", f"the main reading {main_reading!r} is no reading of {', '.join(ledgers)}, "
                                            f"but reading {reading!r} gives every main row's result: name it as the "
                                            "main reading"))
                break
    if main_reading and not ledger and not ledgers:
        out.append(Problem(tid, "", f"records the main reading {main_reading!r} but no readings ledger is exported "
                                    "(a missing ledger switches no check off)"))
    if ledgers and not (main_reading and meta.get("main_reading_evidence")):
        out.append(Problem(tid, "", f"has the readings ledger {', '.join(ledgers)} but records no main_reading with "
                                    "its printed evidence (compare(..., main_reading=, reading_evidence=))"))
    for r in records:
        q = r["quantity"]
        for reason in _row_problems(tid, r, root, ledger, bool(ledgers), meta.get("notebook", "")):
            out.append(Problem(tid, q, reason))
        if main_reading and main_reading in readings and q in readings[main_reading]:
            lr = readings[main_reading][q]
            # the same reading on the same side of the print (a ledger may repeat a Monte Carlo with fewer
            # runs, so its digits may differ; its verdict may not)
            if (lr["status"] in vd.REACHING) != (r["status"] in vd.REACHING):
                out.append(Problem(tid, q, f"the main reading's ledger row says {lr['status']} "
                                           f"({lr['reproduced'] or lr['reproduced_text']}), the table {r['status']} "
                                           f"({r['reproduced'] or r['reproduced_text']}): the two must be one computation"))
        in_ledger = any(q in per for per in readings.values())
        if ledgers and r["status"] == "unverifiable" and in_ledger and \
                not ledger_evidence(q, df, meta, readings, by_q).reaching:
            out.append(Problem(tid, q, "unverifiable although the ledger tries this value and no reading reaches the "
                                       "print: that is not-reproduced"))
        if ledgers and r["status"] == "not-reproduced" and r.get("basis", "") != "" and not in_ledger:
            out.append(Problem(tid, q, f"not-reproduced but no reading of {', '.join(ledgers)} shows it"))
        if ledgers and r["status"] in ("not-reproduced", "erratum", "unverifiable") and r.get("basis", "") == "":
            ev = ledger_evidence(q, df, meta, readings, by_q)
            if r["status"] in ("not-reproduced", "erratum") and ev.reaching:
                what = ("a misprint that a faithful reading reproduces is an inconsistency or another convention"
                        if r["status"] == "erratum" else "not-reproduced needs every faithful reading to miss the print")
                out.append(Problem(tid, q, f"the row is {r['status']} but reading {ev.reaching[0]!r} reaches the print: {what}; "
                                           "rule the reading out with printed evidence or change the status"))
            if r["status"] == "not-reproduced" and not any(q in per for per in readings.values()):
                out.append(Problem(tid, q, f"not-reproduced but no reading of {', '.join(ledgers)} shows it"))
            if r["status"] == "unverifiable" and not ev.reaching:
                out.append(Problem(tid, q, "unverifiable in a table with a ledger although no reading reaches the "
                                           "print: that is not-reproduced"))
        if r.get("basis", "") != "":
            out += _basis_problems(tid, r, df, meta, readings, root, by_q)
    out += _every_reading_problems(tid, df, meta, ledgers)
    return out


EVERY_READING = re.compile(r"\bunder\s+(every|any|all)\s+(faithful\s+)?readings?\b|"
                           r"\b(every|any|all)\s+(faithful\s+)?readings?\s+(the print allows|tried)\b", re.I)
"""Words that say a verdict holds under all the readings a print allows."""


def _every_reading_problems(tid: str, df: pd.DataFrame, meta: Mapping[str, Any], ledgers: list[str]) -> list[Problem]:
    """"Under every reading" is said only of a not-reproduced verdict of a table whose readings
    ledger exists: the audit then knows that no reading of the ledger (not ruled out) reaches the print."""
    out = []
    if EVERY_READING.search(str(meta.get("summary", ""))) and not (ledgers and (df["status"] == "not-reproduced").any()):
        out.append(Problem(tid, "", "its summary speaks of every reading, but no not-reproduced row of a table with a "
                                    "readings ledger backs it"))
    if _is_ledger(tid):
        return out
    for r in _records(tid):
        backed = r["status"] == "not-reproduced" and (ledgers or r.get("basis", "") == "claim")
        if EVERY_READING.search(str(r["note"])) and not backed:
            out.append(Problem(tid, r["quantity"], f"its note speaks of every reading, but the row is {r['status']}"
                                                   + ("" if ledgers else " in a table without a readings ledger")))
    return out


def _paper_problems(tid: str, df: pd.DataFrame, meta: Mapping[str, Any]) -> list[Problem]:
    """The printed values of a table are the paper file's: its digest is the sidecar's, and every row
    whose quantity the file holds carries the file's number (to the digits stored)."""
    src = meta.get("paper_source")
    if not src:
        return []
    path = rp.data_root() / src
    if not path.exists():
        return [Problem(tid, "", f"its paper source {src} does not exist")]
    out = []
    if meta.get("paper_digest") and hashlib.sha256(path.read_bytes()).hexdigest() != meta["paper_digest"]:
        out.append(Problem(tid, "", f"{src} changed since the table was computed (paper_digest): rerun its notebook"))
    try:
        paper = rp.parse_paper_file(path)
    except rp.RegistryError:
        return out
    values = paper.numeric()
    for r in _records(tid):
        q = r["quantity"]
        if q not in values.index or r["paper"] == "" or not math.isfinite(values[q]):
            continue
        printed, stored = float(values[q]), _num(r["paper"])
        if not math.isclose(printed, stored, rel_tol=1e-6, abs_tol=1e-300) and \
                rp.round_sig(printed, max(1, _sig(r["paper"]))) != stored:
            out.append(Problem(tid, q, f"paper value {r['paper']} is not the printed {printed:g} of {src}"))
    return out


def _rests_on_statuses(refs: list[str]) -> tuple[list[str], list[str]]:
    """The statuses of the rows named by ``<table>#<quantity>`` or ``<table>`` refs, and the refs that name nothing."""
    statuses, missing = [], []
    for ref in refs:
        tid, _, q = ref.partition("#")
        if not (rp.tables_dir() / f"{tid}.csv").exists():
            missing.append(ref)
            continue
        sub = [r["status"] for r in _records(tid) if not q or r["quantity"] == q]
        if not sub:
            missing.append(ref)
        statuses += sub
    return statuses, missing


def _basis_problems(tid: str, r: Mapping[str, Any], df: pd.DataFrame, meta: Mapping[str, Any],
                    readings: Mapping[str, Mapping[str, Mapping[str, Any]]], root: Path,
                    by_q: Mapping[str, Mapping[str, Any]]) -> list[Problem]:
    q = r["quantity"]
    try:
        agrees = vd.parse_agrees(r.get("agrees", ""))
    except ValueError as exc:
        return [Problem(tid, q, str(exc))]
    refs = vd.split_refs(r.get("rests_on", ""))
    statuses, missing = _rests_on_statuses(refs)
    if missing:
        return [Problem(tid, q, f"rests_on names rows that do not exist: {', '.join(missing)}")]
    within = _within(r)
    led = ledger_evidence(q, df, meta, readings, by_q) if readings else None
    ev = vd.Evidence(basis=r["basis"], agrees=agrees, within=within, ledger=led, rests_on=tuple(statuses),
                     has_test=_evidence_ok_once(root, r["evidence"], meta.get("notebook", "")))
    try:
        derived = vd.derive_status(ev)
    except ValueError as exc:
        return [Problem(tid, q, str(exc))]
    out = []
    if derived != r["status"]:
        out.append(Problem(tid, q, f"stored status {r['status']} but its {r['basis']} evidence gives {derived}"))
    if derived == "erratum" and not ev.has_test:
        out.append(Problem(tid, q, "an erratum needs evidence naming a notebook and a test that exist"))
    return out


def audit(table_ids: Iterable[str] | None = None) -> list[Problem]:
    """Every problem of the stored tables (all of them by default).

    Parameters
    ----------
    table_ids : iterable of str, optional

    Returns
    -------
    list of Problem
    """
    d = rp.tables_dir()
    ids = rp.list_tables() if table_ids is None else list(table_ids)
    out = []
    if table_ids is None:
        for csv in sorted(d.glob("*.csv")):
            if csv.stem not in ("status", "register") and not (d / f"{csv.stem}.json").exists():
                out.append(Problem(csv.stem, "", "a CSV without its sidecar: tables are written by compare(), not by hand"))
    for tid in ids:
        out += audit_table(tid)
    if table_ids is None:
        from replication.registry import inventory

        for key in rp.SOURCE_KEYS:
            out += [Problem(f"inventory of {key}", "", msg) for msg in inventory.problems(key)]
    return out


def check(table_ids: Iterable[str] | None = None) -> None:
    """Raise :class:`replication.registry.schema.RegistryError` listing every problem of the stored tables.

    Parameters
    ----------
    table_ids : iterable of str, optional

    Raises
    ------
    RegistryError
    """
    bad = audit(table_ids)
    if bad:
        raise rp.RegistryError(f"{len(bad)} stored rows or tables break the verdict rule or the status criteria "
                               "(CONTRIBUTING.md, \"Statuses\"):\n  - "
                               + "\n  - ".join(map(str, bad)))
