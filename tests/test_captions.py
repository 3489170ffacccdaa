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


def test_chen2019_static_test_purpose_promises_two_tests():
    """reading.md D2: the whole purpose sentence (line 1239) holds two tests, the first naming no
    compensation and the second after it; the caption's 'before' is not contradicted by it."""
    caps = rp.load_paper("chen2019-print-captions").data.set_index("quantity")
    clauses = [c for c in caps.loc["static test purpose", "value"].rstrip("。").split("；") if c.strip()]
    named = [Q.qualifiers(c, "温度补偿([前后])") for c in clauses]
    assert named == [frozenset(), frozenset({"后"})]
    assert Q.qualifiers(caps.loc["Table 4-33 caption", "value"], "温度补偿([前后])") == {"前"}
    t = rp.load_table("chen2019-print-captions").set_index("quantity")
    assert t.loc["Table 4-33 caption against static test purpose", "status"] == "qualitative"
    assert t.loc["Table 4-33 caption against Table 4-33 heading", "status"] == "inconsistent"


def test_chen2019_print_parts_hold_what_an_independent_reading_found():
    """data/paper/chen2019/reading.md F37, F48, F50, F64, F75 and F78: the exported printed-parts table."""
    t = rp.load_table("chen2019-print-parts").set_index("quantity")
    found = ["Table 4-5 caption against Table 4-5 column header", "Table 4-29 caption against Table 4-29 column header",
             "Table 4-5 axis row against Table 4-13 axis row", "Table 4-48 PACF label against Table 3-1 PACF label",
             "symbols of the 45-state list", "sign of the gyro C[2,2] across temperature",
             "sign of the accelerometer C[1,1] across temperature", "volume of [55] against Navigation",
             "volume of [62] against 中国惯性技术学报",
             # the independent reading of §4.1 (reading.md B07, B26)
             "unit of the Table 4-2 scale factor against K_i of (4-1)",
             "unit of the Table 4-6 scale factor against K_{ai} of (4-2)",
             "roll run 1: middle-frame travel of the coordinated turn of step (4)",
             "roll run 2: middle-frame travel of the coordinated turn of step (4)",
             # the independent readings of chs. 1, 5 and 4 §2-§3 (reading.md)
             "volume of [63] against [65]", "year of [60] against 中国惯性技术学报",
             "POS AV/610 specification of Table 4-44 against its accuracy after offline processing in ch. 1"]
    assert (t.loc[found, "status"] == "inconsistent").all()
    assert (t.status == "inconsistent").sum() == len(found) + 2  # Tables 4-13 and 4-21 as 4-5 and 4-29
    # B23: the static g self-checks against the 10 μg of conclusion 2 turn on an unprinted quantity
    b23 = t.loc["compensation of the static self-checks of Table 4-35 against the gravity self-check bound of"
                " conclusion 2"]
    assert b23.status == "unverifiable" and float(b23.reproduced) > float(b23.paper)
    assert t.loc["Table 4-44 15-state row against Table 4-50 normal-gravity column", "status"] == "qualitative"
    assert (t[t.basis == "unstated"].status == "unverifiable").all()
