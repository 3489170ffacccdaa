"""Check that stored notebooks were executed top to bottom with no error and no volatile metadata.

    python scripts/check_notebooks.py NOTEBOOK ...

Strict nbval compares outputs; this check catches what nbval cannot: a notebook whose cells
were run out of order, an error output stored in a cell, a cell never executed, or timing
metadata or the interpreter's version (``language_info.version``) that would make ``make book``
leave ``git status`` dirty.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path


def math_line_problems(text: str) -> list[str]:
    """Lines of an inline formula that Markdown would read as something else: a formula broken
    across lines so that a line starts with ``- `` / ``+ `` / ``* `` (a list item) or ``#``."""
    out, inside = [], False
    for line in text.split("\n"):
        if inside and re.match(r"\s*([-+*]\s|#)", line):
            out.append(f"a line inside $...$ starts with {line.strip()[:2]!r} (rendered as Markdown): {line.strip()[:60]}")
        # an odd number of unescaped single $ (not $$) toggles the inline-math state
        singles = len(re.findall(r"(?<![\\$])\$(?!\$)", line))
        inside ^= singles % 2 == 1
    return out


def problems(path: Path) -> list[str]:
    try:
        nb = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        return [f"unreadable: {exc}"]
    out = []
    version = nb.get("metadata", {}).get("language_info", {}).get("version")
    if version is not None:
        out.append(f"metadata.language_info.version = {version!r} stored: the interpreter's version makes a run on "
                   "another Python rewrite the notebook (run it with scripts/run_notebooks.py, which strips it)")
    code = [c for c in nb.get("cells", []) if c.get("cell_type") == "code"]
    counts = [c.get("execution_count") for c in code]
    if counts != list(range(1, len(code) + 1)):
        out.append(f"not executed top to bottom in one kernel (execution counts {counts[:8]}...)")
    for i, c in enumerate(code, 1):
        if "execution" in c.get("metadata", {}):
            out.append(f"code cell {i}: execution timing metadata stored (run it with scripts/run_notebooks.py)")
        for o in c.get("outputs", []):
            if o.get("output_type") == "error":
                out.append(f"code cell {i}: stored error output {o.get('ename')}")
            if o.get("name") == "stderr":
                text = "".join(o.get("text", ""))
                if "Traceback" in text or "Error" in text:
                    out.append(f"code cell {i}: stderr output with an error: {text.strip()[:120]}")
                elif "Warning" in text:
                    out.append(f"code cell {i}: a warning was printed (fix its cause): {text.strip()[:120]}")
    if not code:
        out.append("no code cells")
    for i, c in enumerate(nb.get("cells", []), 1):
        if c.get("cell_type") == "markdown":
            out += [f"markdown cell {i}: {m}" for m in math_line_problems("".join(c.get("source", "")))]
    return out


def main(argv: list[str]) -> int:
    bad = 0
    for arg in argv:
        for msg in problems(Path(arg)):
            print(f"{arg}: {msg}")
            bad += 1
    print(f"checked {len(argv)} notebooks: {bad} problems")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
