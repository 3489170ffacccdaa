"""The package version and the commit of the build on every page, and each script once.

* Footer: ``replication <version> · built from commit <hash>`` (``+ local changes`` when the
  work tree differs from that commit), so that a reader who cites a number from a page knows which
  state of the package printed it.
* sphinx-thebe registers its configuration script once per read of the sources; a page that
  declares ``THEBE_JS_URL`` twice stops with a JavaScript error.  Identical inline scripts are
  dropped from each page after the first.
"""

from __future__ import annotations

import subprocess
from pathlib import Path


def _git(*args: str, cwd: Path) -> str:
    try:
        return subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def provenance(root: Path) -> str:
    """The footer text: library version and the build's commit."""
    try:
        from replication import __version__ as version
    except ImportError:  # the book is built from the project's environment; say so if not
        version = "(not installed)"
    sha = _git("rev-parse", "--short=12", "HEAD", cwd=root) or "unknown"
    dirty = bool(_git("status", "--porcelain", "--untracked-files=no", "--", "replication", "book", "tables",
                      "data", cwd=root))
    return f"replication {version} · built from commit {sha}" + (" + local changes" if dirty else "")


def _footer(app, config):
    opts = dict(config.html_theme_options or {})
    text = provenance(Path(app.srcdir).parent)
    opts["extra_footer"] = f'<p class="provenance">{text}</p>'
    config.html_theme_options = opts


def _dedupe_scripts(app, pagename, templatename, context, doctree):
    scripts = context.get("script_files")
    if not scripts:
        return
    seen, kept = set(), []
    for s in scripts:
        attrs = getattr(s, "attributes", {}) or {}
        key = (str(getattr(s, "filename", s) or ""), attrs.get("body", ""))  # the same script at another priority too
        if key in seen:
            continue
        seen.add(key)
        kept.append(s)
    context["script_files"] = kept


def setup(app):
    app.connect("config-inited", _footer)
    app.connect("html-page-context", _dedupe_scripts, priority=1000)  # after every other extension
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
