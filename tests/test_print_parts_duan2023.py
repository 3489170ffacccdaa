"""The vector labels of duan2023 against the components they list (replication.papers.duan2023.printed.label_rows)."""

from __future__ import annotations

import pandas as pd
import pytest

from replication.papers.duan2023 import printed


def test_label_and_symbols_are_read_in_order():
    assert printed.label_components("位置误差修正向量(经-纬-高)") == ["longitude", "latitude", "height"]
    assert printed.symbol_components(r"$\delta p^c = [\delta L^c \ \delta \lambda^c \ \delta h^c]^T$") == [
        "latitude", "longitude", "height"]
    assert printed.symbol_components(r"$\phi = [\phi_E \quad \phi_N \quad \phi_U]^T$") == ["east", "north", "up"]
    assert printed.symbol_components(r"$S = [S_x \ S_y]^T$") == ["east", "north"]


def test_rows_agree_only_on_the_same_components_in_the_same_order():
    df = pd.DataFrame({"quantity": ["a label", "a symbols", "b label", "b symbols"],
                       "value": ["失准角向量(东-北-天)", r"$[\phi_E \ \phi_N \ \phi_U]$", "水平(东、北、天向)位移向量",
                                 r"$S = [S_x \ S_y]^T$"], "line": [1, 1, 2, 2]})
    rows = printed.label_rows(df, [("a label", "a symbols"), ("b label", "b symbols")])
    assert [r["agrees"] for r in rows] == [True, False]
    assert all(r["basis"] == "parts" for r in rows)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="no bracketed vector"):
        printed.symbol_components("S_x, S_y")
    with pytest.raises(ValueError, match="names no known axis"):
        printed.symbol_components(r"[q \ S_y]")
    with pytest.raises(ValueError, match="not in the transcription"):
        printed.label_rows(pd.DataFrame({"quantity": [], "value": [], "line": []}), [("x", "y")])
