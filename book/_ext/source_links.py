"""From the book to the code: the repository button on every page and ``[source]`` links in the
library reference.

* The repository is ``replication.repository_url()`` (``[project.urls] Repository`` of
  ``pyproject.toml``, the one place it is written).  ``sphinx: config: html_theme_options`` in
  ``_config.yml`` replaces the theme options Jupyter Book derives from ``repository:`` and
  ``html:``, so the button's address and switch are set here.
* ``sphinx.ext.linkcode`` puts a ``[source]`` link beside every documented function and class:
  ``<repository>/blob/<commit>/<path>#L<first>-L<last>``, at the commit the book is built from
  (the one the page footer names, :mod:`page_provenance`), so the lines are the ones documented.
"""

from __future__ import annotations

import importlib
import inspect
import subprocess
from pathlib import Path

BRANCH = "main"
"""The repository's default branch: the button's target, and the links' when git is unavailable."""


def _commit(root: Path) -> str:
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True,
                              check=True).stdout.strip() or BRANCH
    except (OSError, subprocess.CalledProcessError):
        return BRANCH


def source_url(info: dict, *, base: str, ref: str, root: Path) -> str | None:
    """The address of one documented Python object's source lines, or None (data, or not in
    the repository)."""
    if not info.get("module"):
        return None
    try:
        obj = importlib.import_module(info["module"])
        for part in info.get("fullname", "").split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError):
        return None
    if isinstance(obj, property):
        obj = obj.fget
    obj = getattr(inspect.unwrap(obj), "py_func", obj)      # a numba dispatcher keeps its Python function
    try:
        path = Path(inspect.getsourcefile(obj) or "").resolve()
        lines, first = inspect.getsourcelines(obj)
    except (TypeError, OSError):
        return None
    try:
        rel = path.relative_to(root).as_posix()
    except ValueError:                                       # defined outside the repository
        return None
    return f"{base}/blob/{ref}/{rel}#L{first}-L{first + len(lines) - 1}"


def _configure(app, config):
    from replication import repository_url

    base = repository_url().rstrip("/")
    root = Path(app.srcdir).resolve().parent
    ref = _commit(root)
    opts = dict(config.html_theme_options or {})
    opts.update(repository_url=base, use_repository_button=True, repository_branch=BRANCH, path_to_docs="book")
    config.html_theme_options = opts
    config.linkcode_resolve = lambda domain, info: (source_url(info, base=base, ref=ref, root=root)
                                                    if domain == "py" else None)


def setup(app):
    app.setup_extension("sphinx.ext.linkcode")
    app.connect("config-inited", _configure)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
