"""The reference-list sweep (replication.registry.citations) on small lists whose answer is known,
and on chen2019's transcription against what an independent reading of the report found."""

import pandas as pd
import pytest

from replication.registry import citations as C
from replication.registry import reproduction as rp


def _printed(entries, cites):
    rows = [dict(quantity=f"reference [{n}]", value=e, kind="entry", number=n, line=100 + n, object="")
            for n, e in entries]
    rows += [dict(quantity=f"citation {i}", value=c, kind="citation", number="", line=i, object=o)
             for i, (c, o) in enumerate(cites, 1)]
    return pd.DataFrame(rows)


def test_cited_numbers_expand_ranges_and_lists():
    assert C.cited_numbers("20-26") == tuple(range(20, 27))
    assert C.cited_numbers("37,38") == (37, 38)
    assert C.cited_numbers(" 6 ") == (6,)
    for bad in ("26-20", "a", "3;4"):
        with pytest.raises(ValueError):
            C.cited_numbers(bad)


def test_reversed_page_ranges_are_found_and_dates_are_not_ranges():
    assert C.reversed_pages("Trans. 61(11): 3916-2923") == (3916, 2923)
    assert C.reversed_pages("2010, 58(7): 3692 -3075") == (3692, 3075)
    assert C.reversed_pages("13(6): 301 -315") is None
    assert C.reversed_pages("Brochure, 2008 -04-30") is None


def test_a_small_list_with_every_kind_of_disagreement():
    entries = [(1, "A. Author. One title[J]. J. Nav., 2001, 3(2): 10-20"),
               (2, "B. Writer. Another study of gravity[J]. Geod., 1999, 4: 50-40"),
               (3, "A. Author, One title [J]. J. Nav. , 2001, 3(2): 10 - 20"),
               (4, "C. Nobody. Never cited[M]. Press, 2010")]
    cites = [("1", "Table 1-1 text"), ("2", "Table 1-1 caption"), ("1-3", ""), ("9", "")]
    rows = {r["quantity"]: r for r in C.reference_rows(_printed(entries, cites))}
    assert not rows["reference [1]"]["agrees"] and "same work as [3]" in rows["reference [1]"]["note"]
    assert not rows["reference [2]"]["agrees"] and "50-40" in rows["reference [2]"]["note"]
    assert not rows["reference [4]"]["agrees"] and "never cited" in rows["reference [4]"]["note"]
    assert not rows["citation [9]"]["agrees"]
    assert not rows["source of Table 1-1: caption against text"]["agrees"]
    assert {r["basis"] for r in rows.values()} == {"parts"}


def test_a_clean_list_agrees_everywhere():
    entries = [(1, "A. Author. Inertial navigation[M]. Press, 2001"), (2, "B. Writer. Gravity[J]. Geod., 1999, 4: 40-50")]
    rows = C.reference_rows(_printed(entries, [("1", "Figure 2-1 text"), ("1", "Figure 2-1 caption"), ("2", "")]))
    assert all(r["agrees"] for r in rows) and len(rows) == 3


def test_bad_input_is_refused_with_a_message():
    with pytest.raises(ValueError, match="columns"):
        C.reference_rows(pd.DataFrame({"quantity": ["x"]}))
    with pytest.raises(ValueError, match="twice"):
        C.reference_rows(_printed([(1, "a"), (1, "b")], []))
    with pytest.raises(ValueError, match="threshold"):
        C.duplicate_pairs(pd.DataFrame({"number": [1], "entry": ["a"]}), threshold=0)


def test_chen2019_list_holds_what_an_independent_reading_found():
    """data/paper/chen2019/reading.md, F43, F44 and F70-F73: found by a reader of the report alone."""
    rows = {r["quantity"]: r for r in C.reference_rows(rp.load_paper("chen2019-print-references").data)}
    failing = {q for q, r in rows.items() if not r["agrees"]}
    assert failing == {f"reference [{n}]" for n in (21, 36, 39, 56, 59, 75, 76, 77, 78)} | {
        "citation [109]", "source of Table 1-1: caption against text", "source of Figure 3-1: caption against text"}
    assert "same work as [59]" in rows["reference [36]"]["note"]


def test_volumes_out_of_step_with_their_journal_are_found():
    printed = _printed([(1, "A. X[J]. Jour, 2004, 12(3): 1-2"), (2, "B. Y[J]. Jour, 2007, 15(5): 3-4"),
                        (3, "C. Z[J]. Jour, 2005, 31(6): 5-6"), (4, "D. W[J]. Other, 2006, 32(2): 7-8"),
                        (5, "E. V[J]. Other, 2010, 35(1): 9-10"), (6, "F. U[M]. Press, 2001.")], [])
    rows = {r["quantity"]: r for r in C.volume_rows(printed)}
    assert set(rows) == {"volume of [1] against Jour", "volume of [2] against Jour", "volume of [3] against Jour"}
    assert rows["volume of [3] against Jour"]["agrees"] is False and rows["volume of [3] against Jour"]["reproduced"] == 13
    assert rows["volume of [1] against Jour"]["agrees"] and rows["volume of [2] against Jour"]["agrees"]
    with pytest.raises(ValueError):
        C.volume_rows(printed, same_step=1)


def test_locators_shared_by_two_works_are_found():
    printed = _printed([(1, "A. X[J]. Jour, 2010, 25(6): 714-719"), (2, "B. Y[J]. Other, 1999, 25(6): 714 -719"),
                        (3, "C. Z[J]. Jour, 2005, 25(6): 714-720"), (4, "D. W[M]. Press, 2001.")], [])
    rows = C.locator_rows(printed)
    assert [r["quantity"] for r in rows] == ["locator of [1] against [2]"]
    assert rows[0]["agrees"] is False and "25(6): 714-719" in rows[0]["paper_text"]
    with pytest.raises(ValueError, match="columns"):
        C.locator_rows(printed.drop(columns="line"))


def test_chen2019_shared_locator():
    rows = C.locator_rows(rp.load_paper("chen2019-print-references").data)
    assert [r["quantity"] for r in rows] == ["locator of [35] against [66]"]


def test_year_step_rows_judge_what_volume_rows_cannot():
    printed = _printed([(1, "A. X[J]. Jour, 2006, 32(2): 1-2"), (2, "B. Y[J]. Jour, 2010, 35(1): 3-4"),
                        (3, "C. Z[J]. Fixed, 2004, 12(1): 5-6"), (4, "D. W[J]. Fixed, 2007, 15(3): 7-8"),
                        (5, "E. V[J]. Fixed, 1991, 2: 50 -55"), (6, "F. U[J]. Fixed, 1999, 4: 1-9"),
                        (7, "G. T[J]. Other, 2010, 5(1): 1-2"), (8, "H. S[J]. Other, 2011, 6(1): 1-2")], [])
    rows = {r["quantity"]: r for r in C.year_step_rows(printed)}
    # Jour: 1974 against 1975, no step shared: the pair disagrees; Other agrees, no pair row
    assert set(rows) == {"volume of [1] against [2]", "year of [5] against Fixed", "year of [6] against Fixed"}
    assert rows["volume of [1] against [2]"]["agrees"] is False
    assert "2 journals" in rows["volume of [1] against [2]"]["note"]
    # Fixed: step 1992, so 1991 would be volume -1 and 1999 volume 7
    assert rows["year of [5] against Fixed"]["reproduced"] == -1 and not rows["year of [5] against Fixed"]["agrees"]
    assert rows["year of [6] against Fixed"]["reproduced"] == 7 and rows["year of [6] against Fixed"]["agrees"]
    with pytest.raises(ValueError):
        C.year_step_rows(printed, same_step=1)
    with pytest.raises(ValueError, match="columns"):
        C.year_step_rows(printed.drop(columns="line"))


def test_chen2019_year_steps():
    rows = {r["quantity"]: r for r in C.year_step_rows(rp.load_paper("chen2019-print-references").data)}
    assert set(rows) == {"volume of [63] against [65]", "year of [60] against 中国惯性技术学报"}
    assert not any(r["agrees"] for r in rows.values())


def test_entry_year_and_journal_volume_read_the_printed_form():
    assert C.entry_year("Moritz H. Report, 1978, No.277") == 1978
    assert C.entry_year("no year") is None
    assert C.journal_volume("陈永冰. 影响[J]. 中国惯性技术学报, 2005, 31(6): 21 -25") == ("中国惯性技术学报", 2005, 31)
    assert C.journal_volume("董绪荣. 影响[J]. 中国惯性技术学报, 1991, 2: 50 -55") is None


def test_chen2019_volumes_out_of_step():
    rows = C.volume_rows(rp.load_paper("chen2019-print-references").data)
    bad = sorted(r["quantity"] for r in rows if not r["agrees"])
    assert bad == ["volume of [55] against Navigation", "volume of [62] against 中国惯性技术学报"]


def test_doi_rows_check_the_prefix_the_year_and_shared_suffixes():
    from replication.registry import citations as C

    df = pd.DataFrame({"quantity": ["reference [1]", "reference [2]", "reference [3]"],
                       "value": ["A. X [J]. Ship Electronic Engineering, 2014, 34(2): 47. DOI:10.3969/j.issn.1672-9730.2014.02.013",
                                 "B. Y [J]. J. Traffic, 2011, 11(3): 100. DOI:10.369/j.issn.1672-9730.2014.02.013",
                                 "C. Z [J]. Sensors, 2017, 17(7): 1599. DOI:10.3390/s17071599"],
                       "line": [1, 2, 3]})
    rows = {r["quantity"]: r for r in C.doi_rows(df)}
    assert rows["DOI of reference [1]"]["agrees"] and rows["DOI of reference [3]"]["agrees"]
    bad = rows["DOI of reference [2]"]
    assert not bad["agrees"] and "10.369" in bad["note"] and "2014" in bad["note"] and "2011" in bad["note"]
    assert not rows["DOI suffix shared by reference [1] and reference [2]"]["agrees"]
    with pytest.raises(ValueError, match="prints no 'DOI:'"):
        C.doi_rows(df.assign(value="no doi here"))
