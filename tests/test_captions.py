"""Captions against the text around their tables (replication.registry.captions)."""

import pandas as pd
import pytest

from replication.registry import captions as Q
from replication.registry import reproduction as rp

ROLL = dict(pattern="([无带有])横滚角", synonyms={"带": "有"})


def test_qualifiers_map_synonyms_and_need_a_group():
    assert Q.qualifiers("实验一 (无横滚角) 实验二 (有横滚角) 实验三 (带横滚角)", **ROLL) == {"无", "有"}
    assert Q.qualifiers("no qualifier here", **ROLL) == frozenset()
    with pytest.raises(ValueError, match="group"):
        Q.qualifiers("x", "横滚角")


def test_a_disagreeing_and_an_agreeing_caption():
    printed = pd.DataFrame({"quantity": ["T1 caption", "T1 section", "T2 caption", "T2 section"],
                            "value": ["无横滚角时", "带横滚角的仿真", "无横滚角时", "无横滚角的仿真"], "line": [1, 2, 3, 4]})
    rows = Q.qualifier_rows(printed, [dict(caption="T1 caption", against="T1 section", **ROLL),
                                      dict(caption="T2 caption", against="T2 section", **ROLL)])
    assert [r["agrees"] for r in rows] == [False, True] and {r["basis"] for r in rows} == {"parts"}


def test_a_part_without_a_qualifier_or_missing_is_refused():
    printed = pd.DataFrame({"quantity": ["a", "b"], "value": ["无横滚角", "nothing"], "line": [1, 2]})
    with pytest.raises(ValueError, match="finds no qualifier"):
        Q.qualifier_rows(printed, [dict(caption="a", against="b", **ROLL)])
    with pytest.raises(ValueError, match="not in the transcription"):
        Q.qualifier_rows(printed, [dict(caption="a", against="c", **ROLL)])


def test_chen2019_captions_hold_what_an_independent_reading_found():
    """data/paper/chen2019/reading.md F58 and F60, found by a reader of the report alone."""
    caps = rp.load_paper("chen2019-print-captions").data
    temp = dict(pattern="温度补偿([前后])")
    rows = Q.qualifier_rows(caps, [dict(caption="Table 4-33 caption", against="Table 4-33 heading", **temp),
                                   dict(caption="Table 4-38 caption", against="Table 4-38 section", **ROLL),
                                   dict(caption="Table 4-37 caption", against="Table 4-37 section", **ROLL)])
    assert [r["agrees"] for r in rows] == [False, False, True]


def test_chen2019_print_parts_hold_what_an_independent_reading_found():
    """data/paper/chen2019/reading.md F37, F48, F50, F64, F75 and F78: the exported printed-parts table."""
    t = rp.load_table("chen2019-print-parts").set_index("quantity")
    found = ["Table 4-5 caption against Table 4-5 column header", "Table 4-29 caption against Table 4-29 column header",
             "Table 4-5 axis row against Table 4-13 axis row", "Table 4-48 PACF label against Table 3-1 PACF label",
             "symbols of the 45-state list", "sign of the gyro C[2,2] across temperature",
             "sign of the accelerometer C[1,1] across temperature", "volume of [55] against Navigation",
             "volume of [62] against 中国惯性技术学报"]
    assert (t.loc[found, "status"] == "inconsistent").all()
    assert (t.status == "inconsistent").sum() == len(found) + 2  # Tables 4-13 and 4-21 as 4-5 and 4-29
    assert t.loc["Table 4-44 15-state row against Table 4-50 normal-gravity column", "status"] == "qualitative"
    assert (t[t.basis == "unstated"].status == "unverifiable").all()
