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
