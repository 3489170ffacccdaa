"""``json-table``: a benchmark record (a JSON file of the repository) shown as a table.

    ```{json-table} ../../benchmarks/polar.json
    :caption: Both 20-run Monte Carlos of the polar grid INS
    ```

Nested keys are joined with " › "; lists are written inline; numbers keep three significant
digits (timings and ratios on a shared machine carry no more), counts are written whole.
"""

from __future__ import annotations

import json
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive, directives


def _fmt(v) -> str:
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return f"{v:,}".replace(",", " ")
    if isinstance(v, float):
        return f"{v:.3g}"
    if isinstance(v, list):
        return ", ".join(_fmt(x) for x in v)
    return str(v)


def flatten(obj, prefix: str = "") -> list[tuple[str, str]]:
    """(dotted key, formatted value) rows of a nested JSON object, in file order."""
    rows = []
    for k, v in obj.items():
        key = f"{prefix} › {k}" if prefix else str(k)
        if isinstance(v, dict):
            rows += flatten(v, key)
        else:
            rows.append((key.replace("_", " "), _fmt(v)))
    return rows


class JsonTable(Directive):
    required_arguments = 1
    option_spec = {"caption": directives.unchanged}

    def run(self):
        env = self.state.document.settings.env
        path = (Path(env.doc2path(env.docname)).parent / self.arguments[0]).resolve()
        env.note_dependency(str(path))
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise self.error(f"json-table: cannot read {path}: {exc}")
        table = nodes.table(classes=["json-table"])
        if "caption" in self.options:
            table += nodes.title(text=self.options["caption"])
        group = nodes.tgroup(cols=2)
        table += group
        group += nodes.colspec(colwidth=3)
        group += nodes.colspec(colwidth=2)
        head = nodes.thead()
        group += head
        row = nodes.row()
        for label in ("quantity", "value"):
            row += nodes.entry("", nodes.paragraph(text=label))
        head += row
        body = nodes.tbody()
        group += body
        for key, val in flatten(data):
            row = nodes.row()
            row += nodes.entry("", nodes.paragraph(text=key))
            row += nodes.entry("", nodes.paragraph(text=val))
            body += row
        return [table]


def setup(app):
    app.add_directive("json-table", JsonTable)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
