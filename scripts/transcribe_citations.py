"""Transcribe a document's reference list and every citation in its text into ``data/paper/<key>/``.

    python scripts/transcribe_citations.py SOURCE.txt KEY --list-heading 主要参考文献

Reads the extracted text of a document (the file the other transcriptions of ``data/paper/<key>/``
cite by line number), and writes ``<key>-print-references.csv``, a paper-value file with

* one row per entry of the reference list: ``quantity`` ``reference [n]``, ``kind`` ``entry``,
  ``value`` the entry as printed, ``number``, ``line``;
* one row per citation in the text before the list: ``quantity`` ``citation <i> (line <line>)``,
  ``kind`` ``citation``, ``value`` the citation as printed (e.g. ``20-26`` or ``37,38``), ``line``,
  ``form`` (``superscript``, ``文献``, ``math``), ``context`` (up to 40 characters before it) and
  ``object``: the table or figure whose caption carries it, or that the sentence names, e.g.
  ``Table 1-1 caption`` or ``Table 1-1 text``.

The files are data, checked by hand after writing; the sweep that compares them is
:mod:`replication.registry.citations`.
"""

from __future__ import annotations

import argparse
import csv
import re
from pathlib import Path

CITE = re.compile(r"\^\{?\[(?P<a>[0-9][0-9,\-– ]*)\]\}?|文献\s*\[(?P<b>[0-9][0-9,\-– ]*)\]|\{\[(?P<c>[0-9]+)\]\}")
ENTRY = re.compile(r"^-\s*\[(\d+)\]\s*(.*)$")
CAPTION = re.compile(r"^(表|图)\s*(\d+-\d+)")
NAMED = re.compile(r"(表|图)\s*(\d+-\d+)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("source", type=Path)
    ap.add_argument("key")
    ap.add_argument("--list-heading", required=True, help="the line that opens the reference list")
    args = ap.parse_args()
    lines = args.source.read_text(encoding="utf-8").splitlines()
    start = next(i for i, s in enumerate(lines) if s.strip() == args.list_heading)
    out = Path("data/paper") / args.key
    refs = [(int(m[1]), m[2].strip(), i + 1) for i, s in enumerate(lines[start:], start) if (m := ENTRY.match(s.strip()))]
    cites = []
    for i, s in enumerate(lines[:start]):
        cap = CAPTION.match(s.strip())
        for m in CITE.finditer(s):
            form = "superscript" if m["a"] else "文献" if m["b"] else "math"
            sentence = re.split(r"[。；]", s[:m.start()])[-1]
            named = NAMED.findall(sentence)
            obj = (f"{'Table' if cap[1] == '表' else 'Figure'} {cap[2]} caption" if cap else
                   f"{'Table' if named[-1][0] == '表' else 'Figure'} {named[-1][1]} text" if named else "")
            cites.append((i + 1, (m["a"] or m["b"] or m["c"]).replace(" ", ""), form,
                          s[max(0, m.start() - 40):m.start()].strip(), obj))
    head = [f"# document: {args.key}", "# location: the reference list and every citation of the text",
            "# section: references and the whole text",
            f"# notes: written by scripts/transcribe_citations.py from the extracted text (the list opens at seed line "
            f"{start + 1}; a citation is ^[n], ^{{[n]}} or 文献[n]) and checked by hand against the print"]
    with open(out / f"{args.key}-print-references.csv", "w", newline="", encoding="utf-8") as fh:
        fh.write("\n".join(head) + "\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["quantity", "unit", "value", "kind", "number", "line", "form", "context", "object"])
        w.writerows([f"reference [{n}]", "", entry, "entry", n, line, "", "", ""] for n, entry, line in refs)
        w.writerows([f"citation {i} (line {line})", "", cited, "citation", "", line, form, ctx, obj]
                    for i, (line, cited, form, ctx, obj) in enumerate(cites, 1))
    print(f"{len(refs)} entries, {len(cites)} citations")


if __name__ == "__main__":
    main()
