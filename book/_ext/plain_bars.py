"""Render a vertical bar in a library docstring as itself.

The library's docstrings write absolute values and magnitudes the way the papers do, ``|x|``.
reStructuredText would read ``|x|`` as a substitution reference; nothing in the docstrings uses
substitutions, so this extension escapes every bar outside literal blocks (after ``::``) and
tables before autodoc parses the docstring.
"""

from __future__ import annotations

import re


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip(" "))


def escape_bars(lines: list[str]) -> list[str]:
    """Escape ``|`` in docstring lines, leaving literal blocks and grid/simple tables alone."""
    out = []
    literal_indent = None  # indentation of the paragraph that opened a literal block
    opener = False
    for line in lines:
        stripped = line.strip()
        if literal_indent is not None:
            if stripped and _indent(line) <= literal_indent:
                literal_indent = None
            else:
                out.append(line)
                continue
        if opener and stripped:
            opener = False
        table_line = stripped.startswith(("|", "+-", "+=")) and stripped.endswith(("|", "+"))
        if "|" in line and not table_line:
            line = re.sub(r"(?<!\\)\|", r"\\|", line)
        out.append(line)
        if stripped.endswith("::"):
            literal_indent = _indent(line)
    return out


def _process(app, what, name, obj, options, lines):
    lines[:] = escape_bars(lines)


def setup(app):
    app.connect("autodoc-process-docstring", _process)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
