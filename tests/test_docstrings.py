"""Every public function, method and class of the library carries a numpydoc docstring
(CONTRIBUTING.md, "Docstrings"): a ``Parameters`` section naming each argument of the signature
with a type (shape and unit in the type or the description), and a ``Returns`` (or ``Yields``)
section with a type wherever the function returns a value.  The API reference renders these
sections (``sphinx.ext.napoleon`` in ``book/_config.yml``).

The rules are read from the objects themselves with ``numpydoc.docscrape``, so a renamed argument
left in the docstring under its old name fails here.
"""
from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import textwrap
import warnings

import pytest
from numpydoc.docscrape import ClassDoc, FunctionDoc

import replication

# modules whose docstrings have not yet been brought to the numpydoc form; the list only shrinks
PENDING: set[str] = set()


def _public_modules():
    for m in pkgutil.walk_packages(replication.__path__, "replication."):
        if any(p.startswith("_") for p in m.name.split(".")[1:]):
            continue
        yield m.name


def _plain(obj):
    """The Python function behind a numba dispatcher or a ``functools`` cache, else the object."""
    return getattr(obj, "py_func", None) or getattr(obj, "__wrapped__", None) or obj


def _returns_value(func) -> bool:
    """True when the function's own body returns or yields something other than ``None``."""
    try:
        src = textwrap.dedent(inspect.getsource(func))
    except (OSError, TypeError):
        return False
    tree = ast.parse(src)
    top = tree.body[0]
    if getattr(top, "returns", None) is not None and ast.unparse(top.returns) in ("None", "NoReturn"):
        return False

    class Finder(ast.NodeVisitor):
        found = False

        def visit_FunctionDef(self, node):       # nested functions do not count
            if node is top:
                self.generic_visit(node)

        visit_AsyncFunctionDef = visit_FunctionDef

        def visit_Lambda(self, node):
            pass

        def visit_Return(self, node):
            if node.value is not None and not (isinstance(node.value, ast.Constant) and node.value.value is None):
                self.found = True

        def visit_Yield(self, node):
            self.found = True

        visit_YieldFrom = visit_Yield

    f = Finder()
    f.visit(top)
    return f.found


def _documented_names(section) -> set[str]:
    names = set()
    for p in section:
        for n in p.name.split(","):
            names.add(n.strip().lstrip("*"))
    return names


def _function_problems(qualname: str, func) -> list[str]:
    func = _plain(func)
    if not (func.__doc__ or "").strip():
        return [f"{qualname}: no docstring"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            doc = FunctionDoc(func)
        except Exception as exc:                 # a malformed section
            return [f"{qualname}: docstring does not parse as numpydoc ({exc})"]
    out = []
    params = [n for n, p in inspect.signature(func).parameters.items() if n not in ("self", "cls")]
    documented = _documented_names(doc["Parameters"]) | _documented_names(doc["Other Parameters"])
    missing = [n for n in params if n not in documented]
    if missing:
        out.append(f"{qualname}: Parameters section lacks {missing}")
    extra = sorted(documented - set(params))
    if extra and not any(p.kind is p.VAR_KEYWORD for p in inspect.signature(func).parameters.values()):
        out.append(f"{qualname}: Parameters section names {extra}, which the signature lacks")
    untyped = [p.name for p in doc["Parameters"] if not p.type.strip()]
    if untyped:
        out.append(f"{qualname}: parameters without a type {untyped}")
    if _returns_value(func) and not (doc["Returns"] or doc["Yields"]):
        out.append(f"{qualname}: returns a value but has no Returns section")
    return out


def _objects(module):
    for name, obj in vars(module).items():
        if name.startswith("_"):
            continue
        plain = _plain(obj)
        if getattr(plain, "__module__", None) != module.__name__:
            continue
        if inspect.isfunction(plain):
            yield name, obj, "function"
        elif inspect.isclass(obj):
            yield name, obj, "class"


def _class_problems(qualname: str, cls) -> list[str]:
    out = []
    if not (cls.__doc__ or "").strip():
        return [f"{qualname}: no docstring"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = ClassDoc(cls, config={"show_class_members": False})
    if issubclass(cls, BaseException):
        return out
    fields = getattr(cls, "__dataclass_fields__", None)
    if fields or hasattr(cls, "_fields"):      # dataclasses and named tuples: their fields
        names = list(fields) if fields else list(cls._fields)
        documented = _documented_names(doc["Attributes"]) | _documented_names(doc["Parameters"])
        missing = [n for n in names if n not in documented]
        if missing:
            out.append(f"{qualname}: Attributes/Parameters section lacks fields {missing}")
    for mname, meth in vars(cls).items():
        if mname.startswith("_") and mname != "__call__":
            continue
        if isinstance(meth, (staticmethod, classmethod)):
            meth = meth.__func__
        if inspect.isfunction(meth):
            out += _function_problems(f"{qualname}.{mname}", meth)
    return out


def _problems(module_name: str) -> list[str]:
    module = importlib.import_module(module_name)
    out = []
    for name, obj, kind in _objects(module):
        qual = f"{module_name}.{name}"
        out += _function_problems(qual, obj) if kind == "function" else _class_problems(qual, obj)
    return out


MODULES = sorted(_public_modules())


@pytest.mark.parametrize("module_name", [m for m in MODULES if m not in PENDING])
def test_numpydoc_sections(module_name):
    problems = _problems(module_name)
    assert not problems, "\n".join(problems[:40]) + (f"\n... {len(problems) - 40} more" if len(problems) > 40 else "")


def test_pending_list_names_real_modules_that_still_fail():
    """A module brought to the numpydoc form leaves PENDING (the list cannot go stale)."""
    unknown = PENDING - set(MODULES)
    assert not unknown, f"PENDING names modules that do not exist: {sorted(unknown)}"
    done = [m for m in sorted(PENDING) if not _problems(m)]
    assert not done, f"these modules pass; remove them from PENDING: {done}"


def test_the_rule_catches_a_missing_parameter_and_return():
    def f(a, b):
        """Sum.

        Parameters
        ----------
        a : float
            First term.
        """
        return a + b

    probs = _function_problems("f", f)
    assert any("lacks ['b']" in p for p in probs)
    assert any("no Returns" in p for p in probs)
