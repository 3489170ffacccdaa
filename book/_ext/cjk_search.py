"""Search that finds a two-character Chinese term inside a longer run of Chinese characters.

Sphinx's English index splits text at non-word characters, so a run of Chinese characters such
as 逆序检验 is one term; the search page matches a query inside a term only when the query has
more than two characters, so 逆序 found nothing.  Chinese has no spaces between words: this
index keeps every run whole and adds each two-character window of it (逆序, 序检, 检验), so a
query of two or more Chinese characters finds the pages that contain it.  Latin text is split
and stemmed exactly as before.
"""

from __future__ import annotations

import re

from sphinx.search.en import SearchEnglish

CJK_RUN = re.compile(r"[\u3400-\u4dbf\u4e00-\u9fff\uf900-\ufaff]+")


def cjk_terms(word: str) -> list[str]:
    """The Chinese runs of ``word`` and every two-character window of each run."""
    out = []
    for run in CJK_RUN.findall(word):
        if run != word:
            out.append(run)
        if len(run) > 2:
            out += [run[i:i + 2] for i in range(len(run) - 1)]
    return out


class SearchEnglishCJK(SearchEnglish):
    """English search with Chinese runs indexed whole and as bigrams."""

    lang = "en"

    def split(self, input: str) -> list[str]:
        words = super().split(input)
        extra = [t for w in words if CJK_RUN.search(w) for t in cjk_terms(w)]
        return words + extra


def setup(app):
    app.add_search_language(SearchEnglishCJK)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
