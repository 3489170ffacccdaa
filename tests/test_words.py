"""Words follow the tables (replication/registry/words.py): every count that the landing page's
"In short" and each part's opening state is vouched for by a counts note recomputed from the tables."""

from __future__ import annotations

from pathlib import Path

import pytest

from replication.registry import words

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "book" / "intro.md"] + [ROOT / "book" / k / "index.md" for k in ("chen2019", "fang2020", "duan2023",
                                                                                  "an2021")]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: "/".join(p.parts[-2:]))
def test_the_summaries_follow_the_tables(page):
    assert words.paragraphs(page), f"{page} has no 'In short' section"
    assert words.problems(page) == []


def test_the_readme_counts_follow_the_tables():
    assert words.problems(ROOT / "README.md", heading="") == []


def _page(tmp_path, text):
    p = tmp_path / "book" / "intro.md"
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text("# T\n\n## In short\n\n" + text + "\n\n## Next\n", encoding="utf-8")
    return p


def _table_with_two_failures():
    from replication.registry import reproduction as rp

    for tid in rp.list_tables():
        df = rp.read_table(tid)
        n = int((df["status"] == "not-reproduced").sum())
        if n >= 2:
            return tid, n, len(df)
    pytest.skip("no table with two not-reproduced rows")


def test_a_sentence_that_says_one_bar_while_the_table_has_two_fails(tmp_path):
    tid, n, rows = _table_with_two_failures()
    ok = _page(tmp_path, f"{n} of the {rows} rows do not reproduce. <!-- counts: {tid} not-reproduced={n} rows={rows} -->")
    assert words.problems(ok) == []
    wrong_note = _page(tmp_path, f"one bar does not reproduce. <!-- counts: {tid} not-reproduced=1 -->")
    assert any("the tables" in p for p in words.problems(wrong_note))
    no_note = _page(tmp_path, f"{n} of the {rows} rows do not reproduce.")
    found = words.problems(no_note)
    assert any(f"the count {n}" in p for p in found) and any(f"the count {rows}" in p for p in found)
    unknown = _page(tmp_path, "two rows fail. <!-- counts: chen2019-table-99-99 not-reproduced=2 -->")
    assert any("no table holds" in p for p in words.problems(unknown))


def test_counts_are_told_from_references_and_measurements():
    para = ("Tables 1 and 2 reproduce within 3e-4 °/h; eq. (17) holds; 36 km after 2 h; "
            "nine printed coefficients are wrong and 9 of the 108 verdicts differ; the one reading.")
    assert sorted(words.stated_counts(para)) == [9, 9, 108]
