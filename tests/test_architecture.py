"""The package's four parts and the one-way import rules between them (CONTRIBUTING.md, "Library").

``replication.nav`` (the navigation toolkit) imports nothing else of the package; the paper methods
``replication.papers.<key>`` import the toolkit and their own paper, never another paper;
``replication.crosschecks`` import only the Earth model, the units and the shared checks of the
toolkit (an error of a chapter's code path cannot repeat itself there); ``replication.registry``
knows no physics: it imports neither the toolkit nor the methods, only the package's metadata leaf
``replication._meta`` (version, repository address), which imports nothing of the package.  The rules are read from the
source with ``ast``, so a deferred import inside a function counts too.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "replication"
CROSSCHECK_ALLOWED = {"replication.nav.earth", "replication.nav.units", "replication.nav._validate"}


def _modules():
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        yield ".".join(parts), path


def _imports(name: str, path: Path) -> set[str]:
    """Every module of the package that ``path`` imports (absolute or relative, at any depth)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("replication")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if not mod.startswith("replication"):
                continue
            out.add(mod)
            out |= {f"{mod}.{a.name}" for a in node.names}     # 'from replication.nav import earth'
    known = {n for n, _ in _modules()}
    return {m for m in out if m in known}


def _part(module: str) -> str:
    parts = module.split(".")
    if len(parts) < 2:
        return "top"
    if parts[1] == "papers" and len(parts) > 2 and parts[2] not in ("plots", "symbolic", "sins_error_rates"):
        return f"papers.{parts[2]}"
    return ".".join(parts[:2])


MODULES = dict(_modules())


def test_the_four_parts_are_folders():
    parts = {_part(m) for m in MODULES}
    assert {"replication.nav", "replication.registry", "replication.crosschecks",
            "papers.chen2019", "papers.fang2020", "papers.duan2023", "papers.an2021"} <= parts
    # nothing but the package's entry points lives at the top
    top = {m for m in MODULES if m.count(".") == 1 and _part(m) not in
           {"replication.nav", "replication.registry", "replication.crosschecks", "replication.papers"}}
    assert top == {"replication.__main__", "replication._meta"}


@pytest.mark.parametrize("module", sorted(MODULES))
def test_imports_run_one_way(module):
    imported = _imports(module, MODULES[module])
    part = _part(module)
    bad = set()
    for m in imported:
        target = _part(m)
        if part == "replication.nav":
            ok = target == "replication.nav"
        elif part.startswith("papers."):
            ok = target in ("replication.nav", part, "replication.papers") or m == "replication"
        elif part == "replication.papers":          # plots and the package docstring: any method, no registry
            ok = target.startswith("papers.") or target in ("replication.nav", "replication.papers")
        elif part == "replication.crosschecks":
            ok = m in CROSSCHECK_ALLOWED or m in ("replication.nav", "replication.crosschecks") or \
                target == "replication.crosschecks"
        elif part == "replication.registry":         # the registry and the package's metadata leaf
            ok = target == "replication.registry" or m == "replication._meta"
        elif part == "replication._meta":           # version and repository address: a leaf
            ok = False
        else:                                       # the package itself and the CLI
            ok = target in ("replication.registry", "top", "replication._meta")
        if not ok:
            bad.add(m)
    assert not bad, f"{module} ({part}) imports {sorted(bad)} against the one-way rules"


def test_the_rule_test_can_fail(tmp_path):
    """A planted import of a method into the registry is caught."""
    p = tmp_path / "planted.py"
    p.write_text("from replication.papers.chen2019 import models\n", encoding="utf-8")
    assert "replication.papers.chen2019.models" in _imports("replication.registry.planted", p)


# ---------------------------------------------------------------- verdicts apart from the methods
# "reproduced" is left out: the word also names the reproduced values (a column, an argument)
STATUS_WORDS = {"erratum", "inconsistent", "qualitative", "analog", "unverifiable", "not-reproduced"}

# method modules that still decide statuses; the list only shrinks
STATUS_PENDING: set[str] = set()


def _status_literals(path: Path) -> set[str]:
    """The status words that appear as whole string constants in a module."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and n.value in STATUS_WORDS}


@pytest.mark.parametrize("module", sorted(m for m in MODULES if _part(m).startswith("papers.")))
def test_statuses_are_decided_in_findings_only(module):
    """A paper's methods compute; its ``findings`` module turns the results into the rows the
    chapter hands to the registry (status, note, evidence, corrected text).  No other module of a
    paper writes a status, and none imports its findings."""
    if module.endswith(".findings"):
        users = [m for m, p in MODULES.items() if module in _imports(m, p)]
        assert not users, f"{module} is imported by {users}: the findings are read by notebooks and tests only"
        return
    words = _status_literals(MODULES[module])
    if module in STATUS_PENDING:
        assert words, f"{module} no longer writes statuses: remove it from STATUS_PENDING"
        return
    assert not words, f"{module} writes statuses {sorted(words)}: they belong in its paper's findings module"


# ----------------------------------------------------------------------------- signatures

MAX_ARGUMENTS = 12
# A compiled kernel may take more: numba passes arrays to a compiled function one reference each,
# and a kernel that received a bundle of them took a reference per array at every call (the
# closed-loop filter's hour 0.61 s of CPU against 0.41 s with arrays).  Such a kernel says so in
# its docstring, with this phrase.
ARGUED = "not a bundle"
WHY_ARGUMENTS = "Why these arguments"
SIGNATURES_PENDING: set[str] = set()


def _functions(tree, prefix):
    """(qualified name, node) of every function, nested ones included."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield f"{prefix}.{node.name}", node
            yield from _functions(node, f"{prefix}.{node.name}")
        elif isinstance(node, ast.ClassDef):
            yield from _functions(node, f"{prefix}.{node.name}")


def _n_arguments(node) -> int:
    a = node.args
    names = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]
    names += [x.arg for x in (a.vararg, a.kwarg) if x is not None]
    return len([n for n in names if n not in ("self", "cls")])


def _compiled(node) -> bool:
    return any("njit" in ast.unparse(d) or "jit(" in ast.unparse(d) for d in node.decorator_list)


def _long_signatures():
    out = {}
    for name, path in _modules():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for qual, node in _functions(tree, name):
            if _n_arguments(node) > MAX_ARGUMENTS:
                doc = ast.get_docstring(node) or ""
                argued = _compiled(node) and (ARGUED in doc or WHY_ARGUMENTS in doc)
                out[qual] = (_n_arguments(node), argued)
    return out


def test_no_signature_over_twelve_arguments():
    """No function of the package takes more than twelve arguments, but a compiled kernel that
    argues why (its docstring says the arrays come "not a bundle", or has a "Why these arguments"
    paragraph); option bundles
    (``closedloop.RunOptions``, ``kalman.VerticalChannel``, ...) carry the rest."""
    long = _long_signatures()
    over = {q: n for q, (n, argued) in long.items() if not argued and q not in SIGNATURES_PENDING}
    assert not over, f"signatures over {MAX_ARGUMENTS} arguments (bundle the options): {over}"
    stale = {q for q in SIGNATURES_PENDING if q not in long or long[q][1]}
    assert not stale, f"remove from SIGNATURES_PENDING, they pass now: {sorted(stale)}"


def test_the_signature_rule_can_fail():
    src = "def f(" + ", ".join(f"a{i}" for i in range(13)) + "):\n    pass\n"
    node = ast.parse(src).body[0]
    assert _n_arguments(node) == 13 and not _compiled(node)
    src = "@njit\ndef g(self, " + ", ".join(f"a{i}" for i in range(12)) + "):\n    '''x, not a bundle'''\n"
    node = ast.parse(src).body[0]
    assert _n_arguments(node) == 12 and _compiled(node)


# ------------------------------------------------------------------ the closed-loop filter's compiled functions
# The compiled passes of the closed-loop filter (``replication/nav/closedloop/``) read as sequences of
# concept-named helpers: no compiled function there is over COMPILED_LINES lines (the whole def, its
# docstring included; a long explanation belongs in the module docstring) unless a paragraph of its
# docstring starts with WHY_LONG_FUNCTION, and none takes over MAX_ARGUMENTS arguments unless a
# paragraph starts with WHY_ARGUMENTS (numba takes a reference to each array of a bundle a compiled
# helper receives, so a helper called per step or epoch may take its arrays one by one).
COMPILED_LINES = 60
WHY_LONG_FUNCTION = "Why this function is long"
CLOSED_LOOP = PKG / "nav" / "closedloop"


def _paragraph_starts(doc: str, words: str) -> bool:
    return any(para.strip().startswith(words) for para in re.split(r"\n\s*\n", doc))


def compiled_oversize(source: str) -> dict[str, str]:
    """Each compiled function of ``source`` over COMPILED_LINES lines or MAX_ARGUMENTS arguments
    without the paragraph that argues it, with what is over."""
    out = {}
    for qual, node in _functions(ast.parse(source), ""):
        if not _compiled(node):
            continue
        doc, lines, n_args = ast.get_docstring(node) or "", node.end_lineno - node.lineno + 1, _n_arguments(node)
        over = []
        if lines > COMPILED_LINES and not _paragraph_starts(doc, WHY_LONG_FUNCTION):
            over.append(f"{lines} lines")
        if n_args > MAX_ARGUMENTS and not _paragraph_starts(doc, WHY_ARGUMENTS):
            over.append(f"{n_args} arguments")
        if over:
            out[qual.lstrip(".")] = ", ".join(over)
    return out


def test_closed_loop_compiled_functions_are_short():
    """Every compiled function of the closed-loop filter within 60 lines and 12 arguments, or argued."""
    paths = sorted(CLOSED_LOOP.glob("*.py"))
    assert any("def filter_chunk" in p.read_text(encoding="utf-8") for p in paths)
    found = {f"{p.stem}.{q}": what for p in paths for q, what in compiled_oversize(p.read_text(encoding="utf-8")).items()}
    assert not found, (f"compiled functions over {COMPILED_LINES} lines or {MAX_ARGUMENTS} arguments without a "
                       f"{WHY_LONG_FUNCTION!r} / {WHY_ARGUMENTS!r} paragraph (split them into helpers): {found}")


def test_the_compiled_size_rule_can_fail():
    """A long compiled function and a wide one are caught; the arguing paragraph (not a mention in
    passing) and an uncompiled function pass."""
    args13 = ", ".join(f"a{i}" for i in range(13))
    body = "    x = 1\n" * 60
    src = (f'@njit(**_NJ)\ndef long_one(a):\n    """Doc."""\n{body}\n'
           f'@njit(inline="always")\ndef wide({args13}):\n    """Doc, saying why these arguments."""\n\n'
           f'@njit\ndef argued({args13}):\n    """Doc.\n\n    Why these arguments: one array each."""\n\n'
           f'@njit\ndef argued_long(a):\n    """Doc.\n\n    Why this function is long: one loop."""\n{body}\n'
           f"def plain({args13}):\n{body}")
    assert compiled_oversize(src) == {"long_one": "62 lines", "wide": "13 arguments"}


# ------------------------------------------------------------------ the toolkit knows no paper
# The navigation toolkit is reusable: no identifier or string literal of ``replication.nav`` names
# a source document or one of its printed parts (docstrings, comments and citations aside: a
# docstring says which equation a function implements, a message may cite "chen2019 §3 step 2").
# What a paper prints and how it is repaired lives in ``replication.papers.<key>``.
PAPER_KEYS = ("chen2019", "fang2020", "duan2023", "an2021")
_KEY = re.compile("|".join(PAPER_KEYS), re.IGNORECASE)
_CITATION = re.compile(r"(?:" + "|".join(PAPER_KEYS) + r")(?=\s*(?:eqs?\b|eq\.|§|table\b|fig|ch\b|ch\.|chapter\b|step\b"
                       r"|sec\b|sec\.|section\b|appendix\b|refs?\b|refs?\.|\(|\[))", re.IGNORECASE)
# names of printed parts: eq_3_1, EQ_3_1_DEFECTS, table_2_2, "table-2-2", "eq-2-8", KIND_MISALIGN_T22
_TELL_TALE = re.compile(r"(?:^|[^a-z0-9])(?:eqs?|table|fig)[_ -]?\d+[_-]\d+|(?:^|_)t\d\d(?:_|$)", re.IGNORECASE)


def _docstring_nodes(tree) -> set[int]:
    """ids of the string constants that are docstrings: every bare string statement (module, class,
    function and attribute docstrings) and every assignment to ``__doc__``."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str):
            out.add(id(node.value))
        elif isinstance(node, ast.Assign) and any(isinstance(t, ast.Attribute) and t.attr == "__doc__"
                                                  for t in node.targets):
            out |= {id(n) for n in ast.walk(node.value)}
    return out


def paper_knowledge(source: str) -> list[tuple[int, str]]:
    """(line, text) of every identifier and non-docstring string literal of ``source`` that names a
    paper (a key not followed by a citation's locator) or a printed part of one (:data:`_TELL_TALE`)."""
    tree = ast.parse(source)
    docs = _docstring_nodes(tree)
    out = []
    for node in ast.walk(tree):
        texts = []
        if isinstance(node, ast.Name):
            texts = [node.id]
        elif isinstance(node, ast.Attribute):
            texts = [node.attr]
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            texts = [node.name]
        elif isinstance(node, ast.arg):
            texts = [node.arg]
        elif isinstance(node, ast.keyword) and node.arg:
            texts = [node.arg]
        elif isinstance(node, ast.alias):
            texts = [node.name, node.asname or ""]
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            texts = [node.value]
        for text in texts:
            uncited = len(_KEY.findall(text)) > len(_CITATION.findall(text))
            if uncited or _TELL_TALE.search(text):
                out.append((getattr(node, "lineno", 0), " ".join(text.split())[:90]))
    return sorted(set(out))


def test_the_toolkit_names_no_paper():
    """Every module of ``replication.nav``, each offender reported (file, line, text)."""
    found = {}
    for name, path in sorted(MODULES.items()):
        if _part(name) == "replication.nav":
            hits = paper_knowledge(path.read_text(encoding="utf-8"))
            if hits:
                found[name] = hits
    report = "\n".join(f"{m}:{line}: {text!r}" for m, hits in found.items() for line, text in hits)
    assert not found, f"paper knowledge in the toolkit ({len(found)} modules): move it to replication.papers.<key>\n" \
                      + report


def test_the_paper_rule_can_fail():
    """Planted paper names are caught; citations, comments and docstrings pass."""
    planted = ('"""chen2019 eq. (3-1), as a docstring says."""\n'
               "def eq_3_1_variant(x):  # chen2019\n"
               '    """Table 2-2 of chen2019."""\n'
               '    if x == "table-2-2":\n'
               '        raise ValueError("see chen2019 §3 step 2")\n'
               "    return fang2020_ship(x), K.KIND_MISALIGN_T22, 'replication.papers.an2021.transfer'\n"
               'X = 1\n"""An attribute docstring naming duan2023."""\n')
    hits = {text for _, text in paper_knowledge(planted)}
    assert hits == {"eq_3_1_variant", "table-2-2", "fang2020_ship", "KIND_MISALIGN_T22",
                    "replication.papers.an2021.transfer"}, hits


# ----------------------------------------------------------------------------- long modules
# A module over LONG_LINES lines holds one concept that cannot be cut cleanly, and says why in a
# paragraph of its module docstring that starts with WHY_LONG; otherwise it is split.
LONG_LINES = 900
WHY_LONG = "Why this module is long"
# modules another change is splitting or justifying; the list only shrinks
LONG_PENDING: set[str] = set()


def why_long(source: str) -> str:
    """The paragraph of a module docstring that starts with :data:`WHY_LONG` (empty when none)."""
    doc = ast.get_docstring(ast.parse(source)) or ""
    for para in re.split(r"\n\s*\n", doc):
        if para.strip().startswith(WHY_LONG):
            return " ".join(para.split())
    return ""


def _long_modules() -> dict[str, int]:
    out = {}
    for name, path in MODULES.items():
        n = len(path.read_text(encoding="utf-8").splitlines())
        if n > LONG_LINES:
            out[name] = n
    return out


def test_long_modules_are_split_or_say_why():
    """Every module over LONG_LINES lines argues, in a paragraph of its docstring of at least three
    lines' worth (200 characters), why its one concept is not cut."""
    long = _long_modules()
    unargued = {m: n for m, n in sorted(long.items())
                if m not in LONG_PENDING and len(why_long(MODULES[m].read_text(encoding="utf-8"))) < 200}
    assert not unargued, (f"modules over {LONG_LINES} lines without a {WHY_LONG!r} paragraph (split them, or say why "
                          f"their concept is one): {unargued}")
    stale = sorted(m for m in LONG_PENDING if m not in long or why_long(MODULES[m].read_text(encoding="utf-8")))
    assert not stale, f"remove from LONG_PENDING, they are short or argued now: {stale}"


def test_the_long_module_rule_reads_the_paragraph():
    src = '"""Title.\n\nSome text.\n\nWhy this module is long: one compiled kernel set.\nIt is one concept.\n"""\n'
    assert why_long(src) == "Why this module is long: one compiled kernel set. It is one concept."
    assert why_long('"""Title."""\n') == ""
