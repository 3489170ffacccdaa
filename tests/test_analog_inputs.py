"""chen2019's printed test settings against the analogs' inputs (replication.papers.chen2019.analog_inputs)."""

from __future__ import annotations

import copy

import pytest

from replication.nav.units import DEG
from replication.papers.chen2019 import analog_inputs as AI
from replication.registry import reproduction as rp


@pytest.fixture(scope="module")
def inputs():
    return rp.load_paper(AI.TABLE)


@pytest.fixture(scope="module")
def rows(inputs):
    return {r["quantity"]: r for r in AI.analog_input_rows(inputs, rp.load_paper)}


def _within(r):
    # the row's own tolerance (0, or 1e-9 relative for a unit conversion), stated before comparing
    scale = abs(r["paper"]) if r.get("tolerance_kind") == "rel" else 1.0
    return abs(r["reproduced"] - r["paper"]) <= r["tolerance"] * scale


def test_every_value_row_reads_the_code_within_its_tolerance(rows):
    values = [r for r in rows.values() if r["basis"] == "value"]
    assert len(values) == 19
    assert all(_within(r) for r in values)


def test_a_changed_static_run_length_misses_the_print(inputs, monkeypatch):
    # the length of the static analog runs is read from the library, not typed into the row
    assert _within(AI.analog_input_rows(inputs, rp.load_paper)[-1])
    monkeypatch.setattr(AI.static_tests, "RUN_DURATION_S", 3600.0)
    got = {r["quantity"]: r for r in AI.analog_input_rows(inputs, rp.load_paper)}
    assert got["static test duration"]["reproduced"] == 1.0 and not _within(got["static test duration"])


def test_the_stand_ins_name_another_value(rows):
    stand = {q: r for q, r in rows.items() if r["basis"] == "stand-in"}
    assert {q.split(": ")[-1] for q in stand if "Table 4-43" in q} == {
        "GNSS rate", "GNSS position accuracy", "gyro bias repeatability"}
    assert all(r["reproduced"] != r["paper"] for r in stand.values())


def test_printed_parts_agree_and_temperatures_are_read(rows):
    parts = [r for r in rows.values() if r["basis"] == "parts"]
    assert len(parts) == 13 and all(r["agrees"] for r in parts)
    assert AI.printed_temperatures(rp.load_paper) == [-25, -10, 5, 20]


def test_a_drifted_setting_misses_the_print(inputs, monkeypatch):
    real = AI.turntable_chen2019
    monkeypatch.setattr(AI, "turntable_chen2019", lambda e, **kw: real(e, outer_rate=10 * DEG, **kw))
    got = {r["quantity"]: r for r in AI.analog_input_rows(inputs, rp.load_paper)}
    assert not _within(got["turntable outer-axis rate"])
    assert _within(got["turntable middle-axis rate"])


def test_bad_input_is_refused(inputs):
    short = copy.copy(inputs)
    short.data = inputs.data[inputs.data.quantity != "turntable repeats"]
    with pytest.raises(ValueError, match="no quantity 'turntable repeats'"):
        AI.analog_input_rows(short, rp.load_paper)
    with pytest.raises(ValueError, match="not a calibration table"):
        AI.printed_temperatures(rp.load_paper, tables=[41])
