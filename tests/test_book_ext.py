"""The book's small Sphinx extensions (book/_ext): figure alt text, Chinese search terms, numpydoc scope,
the tokens of table cells kept whole, the nodes of a page owned by its document."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "book" / "_ext"))

from cjk_search import SearchEnglishCJK, cjk_terms  # noqa: E402
from doctree_owner import own_nodes  # noqa: E402
from figure_alt import MAX_CHARS, first_sentence  # noqa: E402
from napoleon_scope import process_docstring  # noqa: E402
from table_tokens import protect_html, protected, split_text, status_words  # noqa: E402


def test_first_sentence_skips_the_periods_of_abbreviations():
    cap = ("Reproduction of Fig. 2: zeros (o) and poles (x) of eqs. (4) and (5) for north-south motion\n"
           "(upper half-plane). The conjugates mirror them.")
    assert first_sentence(cap) == ("Reproduction of Fig. 2: zeros (o) and poles (x) of eqs. (4) and (5) "
                                   "for north-south motion (upper half-plane).")
    assert first_sentence("Bode plot of H_y(s). The dotted line marks it.") == "Bode plot of H_y(s)."
    assert first_sentence("Analog of Fig. 6: 3-D position error.") == "Analog of Fig. 6: 3-D position error."
    assert first_sentence("逆序检验的结果。第二句") == "逆序检验的结果。"


def test_first_sentence_cuts_a_long_caption_at_a_word():
    out = first_sentence("word " * 200)
    assert len(out) <= MAX_CHARS + 2 and out.endswith(" …")


def test_first_sentence_refuses_a_non_string():
    with pytest.raises(TypeError, match="text must be a str"):
        first_sentence(None)


def test_chinese_runs_are_indexed_whole_and_as_bigrams():
    assert cjk_terms("逆序检验") == ["逆序", "序检", "检验"]
    assert cjk_terms("ADF") == []
    words = SearchEnglishCJK({}).split("the 逆序检验 (reverse arrangement test) and 截尾")
    assert {"逆序检验", "逆序", "检验", "截尾", "reverse", "test"} <= set(words)
    assert words.count("截尾") == 1           # a two-character run is its own only window


def test_napoleon_renders_sections_of_functions_and_leaves_constants_plain():
    from types import SimpleNamespace

    from sphinx.ext.napoleon import Config

    app = SimpleNamespace(config=Config(napoleon_google_docstring=False, napoleon_numpy_docstring=True,
                                        napoleon_use_param=False, napoleon_use_rtype=False))
    const = ["Ellipsoidal heights (m) accepted by the functions: from the trench to space."]
    lines = list(const)
    process_docstring(app, "data", "m.HEIGHT_RANGE", None, {}, lines)
    assert lines == const                      # no ":type: Ellipsoidal heights (m) ..."
    lines = ["Radii.", "", "Parameters", "----------", "lat : float", "    Latitude [rad].",
             "", "Returns", "-------", "r : float", "    Radius [m]."]
    process_docstring(app, "function", "m.radii", None, {}, lines)
    text = "\n".join(lines)
    assert ":Parameters: **lat** (*float*)" in text and ":returns: **r** (*float*)" in text


def test_numbers_status_words_and_ids_of_a_table_cell_are_kept_whole():
    statuses = status_words()
    assert {"reproduced", "not-reproduced", "mixed"} <= statuses
    assert protected("0.00011051871") and protected("-1.5e-05") and protected("(4-3)-(4-8)")
    assert protected("chen2019-table-4-33") and protected("not-reproduced", statuses)
    assert protected("reproduced;", statuses) and not protected("noise-free", statuses)
    text = "printed 0.00011051871, not-reproduced: see chen2019-table-4-33 (noise-free)"
    pieces = split_text(text, statuses)
    assert "".join(p for p, _ in pieces) == text
    assert [p for p, keep in pieces if keep] == ["0.00011051871,", "not-reproduced:", "chen2019-table-4-33"]
    assert split_text("plain prose only", statuses) == [("plain prose only", False)]
    # a Chinese sentence breaks between its characters: only its non-Chinese runs with a digit stay whole
    cjk = "文献[15-17]利用大气数据信息,建立一阶马尔可夫过程"
    pieces = split_text(cjk, statuses)
    assert "".join(p for p, _ in pieces) == cjk
    assert [p for p, keep in pieces if keep] == ["[15-17]"]


def test_a_token_that_is_not_a_string_is_refused():
    with pytest.raises(TypeError, match="token must be a str"):
        protected(3)


def test_the_text_cells_of_a_notebook_table_are_marked_too():
    html = ('<table><tr><th>1.5e-05</th><td>±5/±10/±20 °/s</td><td class="x">not-reproduced</td>'
            '<td><b>x 1</b></td></tr></table>')
    out = protect_html(html, status_words())
    assert ('<th><span class="nowrap">1.5e-05</span></th><td><span class="nowrap">±5/±10/±20</span> °/s</td>'
            '<td class="x"><span class="nowrap">not-reproduced</span></td><td><b>x 1</b></td>') in out
    with pytest.raises(TypeError, match="html must be a str"):
        protect_html(None)


def test_nodes_of_another_document_are_pointed_at_the_page():
    from docutils import nodes
    from docutils.utils import new_document

    page, other = new_document("page"), new_document("other")
    para = nodes.paragraph("", "")
    para += nodes.Text("docstring")
    page += para
    para.document = para[0].document = other   # as a nested parse leaves them
    assert own_nodes(None, page) == 2
    assert para.document is page and para[0].document is page and own_nodes(None, page) == 0


def _foreign_documents(doctree) -> int:
    return len({id(n.__dict__["_document"]) for n in doctree.findall()
                if n.__dict__.get("_document", doctree) is not doctree})


@pytest.mark.parametrize("with_extension", [False, True])
def test_an_autodoc_page_in_myst_pickles_without_the_build_environment(tmp_path, with_extension):
    """An ``eval-rst`` automodule in a MyST page: without the extension its nodes keep the
    document autodoc parsed them into (and, pickled, the build environment its settings hold)."""
    import pickle

    from sphinx.application import Sphinx
    from sphinx.util.docutils import docutils_namespace

    src = tmp_path / "src"
    src.mkdir()
    ext = ', "doctree_owner"' if with_extension else ""
    (src / "conf.py").write_text(f'extensions = ["myst_parser", "sphinx.ext.autodoc"{ext}]\n', encoding="utf-8")
    (src / "index.md").write_text("# Page\n\n```{eval-rst}\n.. automodule:: json\n   :members: dumps\n```\n",
                                  encoding="utf-8")
    with docutils_namespace():   # the directives myst_parser registers do not outlive the build
        Sphinx(str(src), str(src), str(tmp_path / "out"), str(tmp_path / "doctrees"), "html", status=None,
               warning=None, freshenv=True).build()
    doctree = pickle.loads((tmp_path / "doctrees" / "index.doctree").read_bytes())
    assert "dumps" in doctree.astext()
    assert (_foreign_documents(doctree) == 0) is with_extension
