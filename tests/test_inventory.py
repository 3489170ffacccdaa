"""The inventory of the print (data/paper/<key>/inventory.csv, replication/registry/inventory.py):
every item has a disposition, every checked item names tables and rows that exist, and the
numbered equations, tables and figures match the counts and the numbering of the document."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from replication.registry import inventory as inv
from replication.registry import reproduction as rp

ROOT = Path(__file__).resolve().parent.parent
KEYS = [k for k in rp.SOURCE_KEYS if (ROOT / "data" / "paper" / k / inv.FILE).exists()]


def test_every_document_has_an_inventory():
    assert KEYS, "no inventory of the print"


@pytest.mark.parametrize("key", KEYS)
def test_the_inventory_is_sound(key):
    assert inv.problems(key) == []


@pytest.mark.parametrize("key", KEYS)
def test_numbered_items_match_the_document(key):
    """The header's counts are read off the document; the inventory lists exactly that many numbered
    equations, tables and figures, with no number skipped that the document does not skip."""
    df = inv.load_inventory(key)
    declared = inv.declared_counts(df.attrs["provenance"])
    assert set(declared) == set(inv.NUMBERED), declared
    for kind in inv.NUMBERED:
        assert int(((df["kind"] == kind) & (df["number"] != "")).sum()) == declared[kind], kind
    assert all(k in set(df["kind"]) for k in ("equation", "table", "claim", "reference")), key


@pytest.fixture()
def copy(tmp_path, monkeypatch):
    shutil.copytree(ROOT / "tables", tmp_path / "tables")
    shutil.copytree(ROOT / "data", tmp_path / "data")
    (tmp_path / "pyproject.toml").write_text("", encoding="utf-8")
    monkeypatch.setenv("REPLICATION_ROOT", str(tmp_path))
    return tmp_path


def _plant(copy, key, edit):
    path = copy / "data" / "paper" / key / inv.FILE
    lines = path.read_text(encoding="utf-8").splitlines()
    path.write_text("\n".join(edit(lines)) + "\n", encoding="utf-8")


def _first_data_line(lines, kind):
    return next(i for i, ln in enumerate(lines) if not ln.startswith("#") and ln.split(",")[1:2] == [kind])


@pytest.mark.parametrize("key", KEYS[:1])
@pytest.mark.parametrize("plant, words", [
    ("no disposition", "disposition"),
    ("a row that does not exist", "not exported"),
    ("a numbered equation dropped", "numbered equations"),
    ("a reason removed", "needs a reason"),
])
def test_a_planted_inventory_fault_is_refused(copy, key, plant, words):
    df = inv.load_inventory(key)
    if plant == "no disposition":
        item = df["item"].iloc[0]
        _plant(copy, key, lambda ls: [ln.replace(",checked,", ",,", 1) if ln.startswith(item + ",") else ln
                                      for ln in ls])
    elif plant == "a row that does not exist":
        item = df.loc[df["disposition"] == "checked", "item"].iloc[0]
        _plant(copy, key, lambda ls: [ln.replace(",checked,", ",checked,chen2019-table-99-99; ", 1)
                                      if ln.startswith(item + ",") else ln for ln in ls])
    elif plant == "a numbered equation dropped":
        _plant(copy, key, lambda ls: [ln for i, ln in enumerate(ls) if i != _first_data_line(ls, "equation")])
    else:
        sub = df[(df["disposition"] != "checked") & ~df["reason"].str.contains(",|\"", regex=True)]
        row = sub.iloc[0]
        _plant(copy, key, lambda ls: [ln[: -len(row["reason"])] if ln.startswith(row["item"] + ",")
                                      and ln.endswith(row["reason"]) else ln for ln in ls])
    found = inv.problems(key)
    assert any(words in p for p in found), found
    from replication.registry import audit

    assert any(words in str(p) for p in audit.audit()), "index must refuse it too"


def test_numbering_gaps_are_found():
    import pandas as pd

    df = pd.DataFrame({"kind": ["table"] * 4, "number": ["1-1", "1-2", "1-4", "2-1"]})
    assert inv.numbering_gaps(df, "table") == ["1-3"]
