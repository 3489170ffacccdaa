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
    if parts[1] == "papers" and len(parts) > 2 and parts[2] not in ("plots",):
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
                argued = _compiled(node) and ARGUED in (ast.get_docstring(node) or "")
                out[qual] = (_n_arguments(node), argued)
    return out


def test_no_signature_over_twelve_arguments():
    """No function of the package takes more than twelve arguments, but a compiled kernel that
    argues why (its docstring says the arrays come "not a bundle"); option bundles
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
