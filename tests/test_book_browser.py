"""Open the built book in headless Chromium, offline, and check what a reader sees.

Every page: loads without a request leaving the machine or failing, raises no JavaScript error,
leaves no raw ``$``/LaTeX outside rendered maths, shows no figure twice, and every local link
(with its ``#anchor``) resolves.  The status page, each part's page and one chapter per paper:
at 1280 px no table with a status column wider than it needs to be and its status column in
sight, the status bars and the findings boxes present.  Math renders with the local MathJax;
figures decode.  What a reader sees first: the landing page states the verdicts (the "In short"
sentences of ``book/intro.md``) and links the repository; on the register, the status page, the
execution report and a few chapters with tables, no table or register is wider than the content
column unless its numbers, status words and ids do not fit in it unbroken (then it scrolls in its
own box), and the column itself does not scroll sideways (scrollWidth against clientWidth,
measured), with the system's fonts and with the widest common ones (:data:`WIDE_FONTS`).  The execution report shows what the machine that ran the book recorded: it is also built from a
record of another machine (long CPU names, run times of hours, failed and timed-out runs, 1 and 16
cores, 69 notebooks) and measured at 1280 and 390 px, so that no check depends on who ran the book.
Every page is also read as a reader reads it (:func:`reader_problems`), at 1280 px and on a phone
(390 px): no number, status word or id of a table broken across lines, no raw Python output (a
printed dict, a bare True/False, a sympy ``**``, a pandas ``...``, ``-0.0``, a count as ``12.0``),
no code line over 88 characters, no page that scrolls sideways; a table too wide for the column
scrolls inside its own box.  These checks are shown to catch what they look for on a small
synthetic book (:func:`build_planted_book`).

Run after the book is built (``make html-strict``); ``make test`` does both. Every request the
pages make is recorded: any request that leaves the local server, or fails, is an error. A
screenshot of one chapter is kept in ``book/_build/screenshot.png``.
"""

from __future__ import annotations

import contextlib
import functools
import html as html_lib
import http.server
import os
import re
import shutil
import subprocess
import sys
import threading
from pathlib import Path
from urllib.parse import urlparse

import pytest

ROOT = Path(__file__).resolve().parent.parent
HTML = ROOT / "book" / "_build" / "html"
CHROMIUM = os.environ.get("CHROMIUM", shutil.which("chromium") or "/usr/bin/chromium")

pytestmark = pytest.mark.browser


def _pages() -> list[Path]:
    pages = sorted(p for p in HTML.rglob("*.html") if p.name not in {"genindex.html", "search.html"}
                   and "_static" not in p.parts and "_sources" not in p.parts)
    return pages


@contextlib.contextmanager
def _serving(directory: Path):
    """A local HTTP server of ``directory``; yields its address."""
    handler = functools.partial(_QuietHandler, directory=str(directory))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{httpd.server_address[1]}"
    finally:
        httpd.shutdown()


@pytest.fixture(scope="module")
def server():
    if not (HTML / "index.html").exists():
        pytest.fail("the book is not built: run `make html-strict` (part of `make test`) first")
    with _serving(HTML) as url:
        yield url


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):  # keep the test output readable
        pass


@pytest.fixture(scope="module")
def browser():
    if not Path(CHROMIUM).exists():
        pytest.fail(f"Chromium not found at {CHROMIUM}: install Debian's 'chromium' (make sysdeps does)")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        b = pw.chromium.launch(
            executable_path=CHROMIUM,
            args=["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync"],
        )
        yield b
        b.close()


class _Visitor:
    """One tab that visits page after page (one renderer process instead of one per page),
    recording per visit the requests that leave the machine, the failed requests and the
    JavaScript errors."""

    SIZE = {"width": 1280, "height": 900}

    def __init__(self, browser):
        self.page = browser.new_page(viewport=dict(self.SIZE))
        self.external, self.failed, self.errors = [], [], []
        self.page.on("pageerror", lambda exc: self.errors.append(str(exc)))
        self.page.on("console", lambda msg: self.errors.append(msg.text) if msg.type == "error" else None)
        self.page.on("request", self._on_request)
        self.page.on("requestfailed", lambda req: self.failed.append(f"{req.url} ({req.failure})"))
        self.page.on("response", lambda resp: self.failed.append(f"{resp.url} (HTTP {resp.status})")
                     if resp.status >= 400 else None)

    def _on_request(self, req):
        if req.url.startswith(("data:", "blob:", "about:")):
            return
        if urlparse(req.url).hostname not in ("127.0.0.1", "localhost"):
            self.external.append(req.url)

    def visit(self, url: str):
        """Load ``url`` until the network is idle, at 1280 px; returns the page (the same tab every
        time)."""
        if self.page.viewport_size != self.SIZE:     # left at a phone's width by the last page
            self.page.goto("about:blank")
            self.page.set_viewport_size(self.SIZE)
        self.external, self.failed, self.errors = [], [], []
        self.page.goto(url, wait_until="networkidle", timeout=60_000)
        return self.page


RAW_TEX = re.compile(r"\$|\\(frac|mathrm|mathbf|left|right|begin|end|sqrt|delta|phi|omega)\b")
"""What must not be left in the visible text once MathJax has run."""

VISIBLE_TEXT_JS = """() => {
  const art = document.querySelector('.bd-article') || document.body;
  const c = art.cloneNode(true);
  c.querySelectorAll('pre, code, mjx-container, script, style, .cell_input, .MathJax, .math').forEach(e => e.remove());
  return c.innerText;
}"""

WAIT_MATH_JS = "() => (window.MathJax && MathJax.startup && MathJax.startup.promise) ? MathJax.startup.promise.then(() => true) : true"


def _local_link_problems(page_path: Path) -> list[str]:
    """Local links of a built page whose file or ``#anchor`` does not exist."""
    text = page_path.read_text(encoding="utf-8")
    problems = []
    for href in set(re.findall(r'href="([^"]+)"', text)):
        href = html_lib.unescape(href)
        if href.startswith(("http:", "https:", "mailto:", "javascript:", "data:")):
            continue
        target, _, frag = href.partition("#")
        target = target.split("?")[0]
        path = (page_path.parent / target).resolve() if target else page_path
        if path.is_dir():
            path = path / "index.html"
        if not path.exists():
            problems.append(f"{href} (no such file)")
        elif frag and path.suffix == ".html" and f'id="{frag}"' not in path.read_text(encoding="utf-8"):
            problems.append(f"{href} (no such anchor)")
    return sorted(problems)


def _chapter_of_each_paper() -> list[str]:
    out = []
    for part in ("chen2019", "fang2020", "duan2023", "an2021"):
        chapters = sorted(p for p in (HTML / part).glob("*.html") if p.name != "index.html")
        assert chapters, f"no chapter page for {part}"
        out.append(chapters[-1].relative_to(HTML).as_posix())
    return out


FIGURES_JS = "Array.from(document.images).filter(i => i.src.includes('_images/')).map(i => i.naturalWidth)"
MATHJAX_SRC_JS = "Array.from(document.scripts).map(s => s.src).filter(s => s.includes('mathjax'))"
FINDINGS = ".admonition:has(.admonition-title:text('Findings of this chapter'))"
OVERVIEW = ["status.html"] + [f"{p}/index.html" for p in ("chen2019", "fang2020", "duan2023", "an2021")]

WIDTH_PAGES = ["register.html", "status.html", "appendix/execution.html", "appendix/exports.html",
               "foundations/01_earth_normal_gravity.html", "chen2019/02_imu_error_model_and_calibration.html",
               "fang2020/01_polar_grid_calibration.html", "an2021/01_gravity_to_attitude.html"]
"""Pages whose every table (registers, comparisons, the execution report) is measured at 1280 px
(:func:`_table_problems`)."""

WIDTH_JS = """(withStatusOnly) => {
  const art = document.querySelector('.bd-article');
  const box = art.getBoundingClientRect();
  const withStatus = t => Array.from(t.querySelectorAll('th')).some(h => h.innerText.trim() === 'status');
  const tables = Array.from(art.querySelectorAll('table')).filter(t => t.offsetParent !== null
      && !t.closest('details:not([open])')
      && (withStatusOnly ? withStatus(t)
          : !t.closest('.cell_output .dataframe, .output .dataframe') && !t.classList.contains('dataframe')));
  return {column: {client: art.clientWidth, scroll: art.scrollWidth, width: Math.round(box.width)},
          tables: tables.map(t => {
            const wrap = t.parentElement;
            const rect = t.getBoundingClientRect();
            const saved = t.style.width;
            t.style.width = '1px';                 // a table is never narrower than its longest tokens
            const narrowest = t.getBoundingClientRect().width;
            t.style.width = saved;
            const status = Array.from(t.tHead ? t.tHead.rows[0].cells : []).find(h => h.innerText.trim() === 'status');
            return {width: Math.round(rect.width), right: rect.right, narrowest: Math.round(narrowest),
                    wrapScroll: wrap.scrollWidth - wrap.clientWidth, box: wrap.clientWidth,
                    scrolls: ['auto', 'scroll'].includes(getComputedStyle(wrap).overflowX),
                    statusRight: status ? status.getBoundingClientRect().right : null,
                    wrapRight: wrap.getBoundingClientRect().right,
                    head: (t.tHead ? t.tHead.innerText : t.innerText).replace(/\\s+/g, ' ').slice(0, 50)};
          }), right: box.right};
}"""
"""The content column's width and overflow, and for each table shown (not in a closed dropdown; with
``true``, only the tables with a status column): its width, its narrowest width (the width of its
longest unbreakable tokens: numbers, status words, ids, see ``book/_ext/table_tokens.py``), its
container's overflow and whether the container scrolls, and where its status column ends.  A data
frame printed by a notebook (``.dataframe``) may scroll and is left out unless it has a status column."""


def _table_problems(m: dict, where: str) -> list[str]:
    """What is wrong with the tables of one measure of :data:`WIDTH_JS`: a table that is wider than
    the content column or its own box (a box in a dropdown or a findings box is narrower) although
    it could be narrower without breaking a token, a wide table whose
    container does not scroll, a status column that a reader must scroll to see, or a content
    column that scrolls sideways.  A table whose narrowest width exceeds the column scrolls inside
    its own box: that is how a table too wide for the page is shown."""
    out = []
    col = m["column"]
    if col["scroll"] > col["client"] + 1:
        out.append(f"{where}: the content column scrolls ({col['scroll']} > {col['client']} px)")
    for t in m["tables"]:
        if not (t["right"] > m["right"] + 2 or t["wrapScroll"] > 2):
            continue
        name = f"{where}: table {t['head']!r} {t['width']} px in a {col['width']} px column"
        if t["narrowest"] < min(col["width"], t["box"]) - 2 or t["width"] > t["narrowest"] + 2:
            out.append(f"{name}, although it fits in {t['narrowest']} px without breaking a token")
        if not t["scrolls"]:
            out.append(f"{name} does not scroll inside its own box")
        if t["statusRight"] is not None and t["statusRight"] > t["wrapRight"] + 2:
            out.append(f"{name}: its status column is out of sight")
    return out


WIDE_FONTS = ("DejaVu Sans", "DejaVu Sans Mono")
"""The widest of the common fonts of a Linux system (fontconfig's defaults on Debian), for text and
code.  The theme asks for the system's fonts, which differ from machine to machine: the tables are
measured with the system's fonts and again with these (:data:`WIDE_FONTS_CSS`), so that the verdict
does not depend on which fonts the machine that runs the check would choose."""

WIDE_FONTS_CSS = (f":root {{ --pst-font-family-base-system: '{WIDE_FONTS[0]}', sans-serif !important; "
                  f"--pst-font-family-monospace-system: '{WIDE_FONTS[1]}', monospace !important; }}")

LANDING = "intro.html"

MAX_CODE = 88
"""The longest line of an input cell a reader sees without scrolling sideways (characters)."""

PHONE = 390
"""A phone's width (CSS px): no page may scroll sideways at it."""

READER_JS = r"""(args) => {
  const art = document.querySelector('.bd-article') || document.body;
  const statuses = new Set(args.statuses);
  const shown = e => e.getClientRects().length > 0;
  // a token broken across lines: the rectangles of its range stand on more than one line
  const twoLines = (node, start, end) => {
    const r = document.createRange(); r.setStart(node, start); r.setEnd(node, end);
    const rects = Array.from(r.getClientRects()).filter(x => x.width > 0.5 && x.height > 0.5);
    if (rects.length < 2) return false;
    const firstBottom = Math.min(...rects.map(x => x.bottom));
    return rects.some(x => x.top >= firstBottom - 1);
  };
  const broken = [];
  art.querySelectorAll('td, th').forEach(cell => {
    if (!shown(cell)) return;
    const walk = document.createTreeWalker(cell, NodeFilter.SHOW_TEXT);
    for (let n = walk.nextNode(); n; n = walk.nextNode()) {
      if (n.parentElement.closest('mjx-container, .MathJax, script, style')) continue;
      const whole = !!n.parentElement.closest('code, .nowrap');
      const re = /\S+/g; let m;
      while ((m = re.exec(n.textContent))) {
        const tok = m[0];
        const bare = tok.replace(/^[.,;:()\[\]]+|[.,;:()\[\]]+$/g, '');
        if (!(whole || /\d/.test(tok) || statuses.has(bare))) continue;
        if (twoLines(n, m.index, m.index + tok.length)) broken.push(tok);
      }
    }
  });
  // the text of the output areas, without inline code and rendered maths
  const outputText = tables => Array.from(art.querySelectorAll('.cell_output')).filter(shown).map(o => {
    const c = o.cloneNode(true);
    c.querySelectorAll('code, mjx-container, .MathJax, .math, script, style' + (tables ? '' : ', table'))
      .forEach(e => e.remove());
    document.body.appendChild(c);        // innerText of a detached element has no line breaks
    const text = c.innerText;
    c.remove();
    return text;
  });
  const outputs = outputText(true), prose = outputText(false);
  // output table cells whose column counts something
  const countCells = [];
  art.querySelectorAll('.cell_output table').forEach(t => {
    const head = t.tHead ? Array.from(t.tHead.rows).pop() : null;
    if (!head || !t.tBodies.length) return;
    const names = Array.from(head.cells).flatMap(h => Array(h.colSpan || 1).fill(h.innerText.trim()));
    Array.from(t.tBodies[0].rows).forEach(row => Array.from(row.cells).forEach((cell, i) => {
      if (new RegExp(args.countColumn, 'i').test(names[i] || '') && /^-?\d+\.0$/.test(cell.innerText.trim()))
        countCells.push(`${names[i]}: ${cell.innerText.trim()}`);
    }));
  });
  const code = Array.from(art.querySelectorAll('.cell_input pre')).flatMap(p => p.innerText.split('\n'))
      .filter(l => l.length > args.maxCode);
  const page = document.scrollingElement;
  return {broken, outputs, prose, countCells, code, scroll: page.scrollWidth, client: page.clientWidth};
}"""
"""What a reader of a page sees, measured: the tokens of table cells broken across lines (a number,
a status word, or anything in code or marked ``.nowrap``: the rectangles of the token's range stand
on two lines), the text of the output areas (without inline code and rendered maths), the cells of
output tables whose column counts something (:data:`COUNT_COLUMN`) written with a ``.0``, the
lines of input cells longer than :data:`MAX_CODE`, and the page's width against the window's."""

COUNT_COLUMN = r"^(n|count|counts|number( of \w+)?|runs|rank|ranks|states|samples|points|segments|fixes)$"
"""Column headings of output tables whose cells are counts: a count is written whole (12, not 12.0)."""

RAW_OUTPUT = {
    "a dict or a set printed as Python writes it": re.compile(r"\{'|\{\"\w"),
    "a numpy scalar's repr": re.compile(r"np\.(?:float|int|bool|str)\w*\(|np\.(?:True|False)_|\barray\(\["),
    "a bare True/False": re.compile(r"^[ \t]*(?:[^\n]*:[ \t]*)?(?:True|False)[ \t]*$", re.M),
    "a Python power (**) outside code and maths": re.compile(r"\w\*\*\w"),
    "a truncation marker (...)": re.compile(r"(?:^|[\s,\[(])\.\.\.(?:[\s,\])]|$)|\w\.\.\.(?:\n|$)|\[\d+ rows x \d+ columns\]"),
    "a negative zero": re.compile(r"(?<![\w.])[-\u2212]0\.0+(?![\d])(?!e[-+]?0*[1-9])"),
}
"""What a reader must not see in an output area.  Only the output areas are searched (never the
prose or the code cells), without inline code and rendered maths: a ``{'`` or ``{"key`` is a printed
dict (a set of braces in prose or a formula does not open with a quote); numpy reprs
(``np.float64(``, ``np.True_``, ``array([``); a line that is, or ends after a colon in, ``True`` or
``False``; ``**`` between two word characters (Markdown has made its bold by then, so one left is a
Python power, e.g. a sympy string); ``...`` standing alone or in a list (pandas and numpy
truncation, not the Unicode ellipsis of a quotation, nor the ``..`` of a range), or ending a line
right after a word (a truncated pandas cell), or pandas' ``[n rows x m columns]``; ``-0.0`` (any
number of zeros; not ``-0.05`` nor ``-0.0e-5``)."""


LINE_RULES = ("a bare True/False", "a Python power (**) outside code and maths")
"""Rules of :data:`RAW_OUTPUT` read on the output text outside tables: a table's row is a line of
its cells, and a boolean column of a data frame is a column, not a printed line; the registry's
comparison tables quote some formulas of their notes as the computer algebra writes them, a matter
of the registry's text (its notes), not of a chapter's output."""


def _statuses() -> list[str]:
    from replication.registry import reproduction

    return sorted(set(reproduction.STATUSES) | set(reproduction.STATUS_COLOURS))


def read_as_a_reader(page, statuses: list[str]) -> dict:
    """Measure ``page`` (loaded, maths rendered) with :data:`READER_JS` at its width and at
    :data:`PHONE` px; the page is left at the phone's width.  Returns the measures of both widths."""
    args = {"statuses": statuses, "maxCode": MAX_CODE, "countColumn": COUNT_COLUMN}
    wide = page.evaluate(READER_JS, args)
    page.set_viewport_size({"width": PHONE, "height": page.viewport_size["height"]})
    return {"wide": wide, "phone": page.evaluate(READER_JS, args)}


def reader_problems(m: dict) -> list[str]:
    """What :func:`read_as_a_reader` found wrong: tokens broken at either width, raw Python
    output (:data:`RAW_OUTPUT`), counts written with ``.0``, code lines over :data:`MAX_CODE`
    characters, and a page that scrolls sideways at :data:`PHONE` px."""
    out = []
    for width, r in (("1280 px", m["wide"]), (f"{PHONE} px", m["phone"])):
        if r["broken"]:
            out.append(f"at {width}, broken across lines: {sorted(set(r['broken']))[:5]}")
    for what, rx in RAW_OUTPUT.items():
        texts = m["wide"]["prose" if what in LINE_RULES else "outputs"]
        hits = [mm.group(0).strip() for text in texts for mm in rx.finditer(text)]
        if hits:
            out.append(f"raw output, {what}: {hits[:3]}")
    if m["wide"]["countCells"]:
        out.append(f"counts written as decimals: {m['wide']['countCells'][:3]}")
    if m["wide"]["code"]:
        out.append(f"{len(m['wide']['code'])} code lines over {MAX_CODE} characters: {m['wide']['code'][0][:60]!r}")
    p = m["phone"]
    if p["scroll"] > p["client"] + 1:
        out.append(f"at {PHONE} px the page scrolls sideways ({p['scroll']} > {p['client']} px)")
    return out


def _in_short() -> list[str]:
    """The opening words (up to the first parenthesis, colon or semicolon) of each "In short" verdict of book/intro.md."""
    text = (ROOT / "book" / "intro.md").read_text(encoding="utf-8")
    section = text.split("## In short", 1)[1].split("\n## ", 1)[0]
    section = section.split("\n\n")[1] if section.startswith("\n\n") else section
    out = []
    for item in re.split(r"^\* ", section, flags=re.M)[1:]:
        plain = re.sub(r"\{\w+\}`([^`<]*)(<[^>]*>)?`", r"\1", item)
        plain = " ".join(plain.replace("**", "").replace("`", "").split())
        out.append(re.split(r"[(:;]", plain, maxsplit=1)[0].strip())
    return out


def _normal(text: str) -> str:
    """Whitespace collapsed, typographic quotes and dashes as typed."""
    for a, b in (("\u2019", "'"), ("\u2018", "'"), ("\u201c", '"'), ("\u201d", '"'), ("\u2013", "--")):
        text = text.replace(a, b)
    return " ".join(text.split())


_CODE_BLOCK = re.compile(r"<pre\b.*?</pre>", re.S)


@pytest.fixture(scope="module")
def seen(server, browser):
    """Every page visited once at 1280 px, with what each test below checks recorded."""
    wide = set(OVERVIEW + _chapter_of_each_paper())
    measured = set(WIDTH_PAGES)
    out = {}
    shot = False
    statuses = _statuses()
    tab = _Visitor(browser)
    for p in _pages():
        rel = p.relative_to(HTML).as_posix()
        text = p.read_text(encoding="utf-8")
        page = tab.visit(f"{server}/{rel}")
        page.evaluate(WAIT_MATH_JS)
        r = dict(external=tab.external, failed=tab.failed, js_errors=tab.errors,
                 raw=sorted(set(m.group(0) for m in RAW_TEX.finditer(page.evaluate(VISIBLE_TEXT_JS)))),
                 imgs=page.evaluate("Array.from(document.images).map(i => i.getAttribute('src'))"
                                    ".filter(s => s && s.includes('_images/'))"),
                 # math outside code listings (MathJax skips <pre>, where a regex may print \( )
                 has_math=r"\(" in _CODE_BLOCK.sub("", text) or "math notranslate" in text,
                 has_figure="<img" in text and "_images/" in text, links=_local_link_problems(p))
        if r["has_math"]:
            r.update(mjx=page.locator("mjx-container").count(), mjx_errors=page.locator("mjx-merror").count(),
                     mathjax_src=page.evaluate(MATHJAX_SRC_JS))
        if r["has_figure"]:
            r["widths"] = page.evaluate(FIGURES_JS)
            if not shot:
                page.screenshot(path=str(ROOT / "book" / "_build" / "screenshot.png"), full_page=False)
                shot = True
        if rel in wide:
            r.update(clipped=page.evaluate(WIDTH_JS, True), bars=page.locator(".status-bar").count(),
                     findings=page.locator(FINDINGS).count())
            if rel == "status.html":
                page.screenshot(path=str(ROOT / "book" / "_build" / "screenshot-status.png"), full_page=False)
        if rel in measured:
            r["widths_measured"] = page.evaluate(WIDTH_JS, False)
            page.add_style_tag(content=WIDE_FONTS_CSS)     # last: the page is left in these fonts
            r["widths_wide_fonts"] = page.evaluate(WIDTH_JS, False)
        if rel == LANDING:
            r["text"] = _normal(page.evaluate("() => document.querySelector('.bd-article').innerText"))
            r["repo_links"] = page.evaluate("""url => Array.from(document.querySelectorAll('a'))
                .filter(a => a.href.replace(/\\/$/, '') === url && a.getClientRects().length > 0).length""",
                                            _repository_url())
        r["reader"] = reader_problems(read_as_a_reader(page, statuses))    # last: leaves a phone's width
        out[rel] = r
    tab.page.close()
    return out


def _repository_url() -> str:
    import replication

    return replication.repository_url().rstrip("/")


def test_the_landing_page_states_the_verdicts_and_links_the_repository(seen):
    """The "In short" verdicts of book/intro.md, one per source document, are on the landing page as
    a reader sees it, and a visible link leads to the repository."""
    r = seen[LANDING]
    verdicts = _in_short()
    assert len(verdicts) == 4 and all(len(v.split()) >= 5 for v in verdicts), verdicts
    missing = [v for v in verdicts if _normal(v) not in r["text"]]
    assert not missing, f"verdicts not shown on {LANDING}: {missing}"
    assert r["repo_links"] >= 1, f"no visible link to {_repository_url()} on {LANDING}"


def test_no_table_or_register_is_wider_than_it_needs_to_be(seen):
    """At 1280 px, with the system's fonts and with :data:`WIDE_FONTS`: the content column does not
    scroll sideways, and a table of the register, the status page, the execution report or a
    chapter is no wider than the column unless its numbers, status words and ids do not fit in it
    unbroken; such a table scrolls inside its own box, its status column in sight
    (:func:`_table_problems`)."""
    problems = []
    for rel, (key, fonts) in ((rel, k) for rel in WIDTH_PAGES
                              for k in (("widths_measured", ""), ("widths_wide_fonts", f" in {WIDE_FONTS[0]}"))):
        problems += _table_problems(seen[rel][key], f"{rel}{fonts}")
    assert any(seen[rel]["widths_measured"]["tables"] for rel in WIDTH_PAGES), "no table measured"
    assert not problems, "\n".join(problems)


def test_every_page_loads_offline(seen):
    """Every page: offline, no failed request, no JavaScript error, no raw TeX, no figure shown
    twice, every local link and anchor resolving."""
    assert len(seen) >= 5, "the book has too few pages"
    problems = []
    for rel, r in seen.items():
        if r["external"]:
            problems.append(f"{rel}: requests leaving the machine: {r['external'][:3]}")
        if r["failed"]:
            problems.append(f"{rel}: failed requests: {r['failed'][:3]}")
        if r["js_errors"]:
            problems.append(f"{rel}: JavaScript errors: {r['js_errors'][:3]}")
        if r["raw"]:
            problems.append(f"{rel}: raw TeX outside rendered maths: {r['raw'][:5]}")
        twice = sorted({i for i in r["imgs"] if r["imgs"].count(i) > 1})
        if twice:
            problems.append(f"{rel}: figures shown twice: {twice[:3]}")
        if r["links"]:
            problems.append(f"{rel}: broken local links: {r['links'][:5]}")
    assert not problems, "\n".join(problems)


def test_overview_and_chapters_fit_at_1280_px(seen):
    """The status page, the part pages and one chapter per paper: at 1280 px no table with a status
    column wider than it needs to be, and its status column in sight (:func:`_table_problems`); the
    status bars on the overview pages; a findings box at the top of each chapter."""
    problems = []
    for rel in OVERVIEW + _chapter_of_each_paper():
        r = seen[rel]
        problems += _table_problems(r["clipped"], rel)
        if rel in OVERVIEW and r["bars"] == 0:
            problems.append(f"{rel}: no status bar")
        if rel not in OVERVIEW and r["findings"] != 1:
            problems.append(f"{rel}: {r['findings']} findings boxes (expected one)")
    assert not problems, "\n".join(problems)


def test_math_is_rendered_by_the_local_mathjax(seen, server):
    with_math = {rel: r for rel, r in seen.items() if r["has_math"]}
    assert with_math, "no page with math found"
    for rel, r in with_math.items():
        assert r["mjx"] > 0, f"{rel}: MathJax rendered nothing"
        assert r["mjx_errors"] == 0, f"{rel}: {r['mjx_errors']} MathJax errors"
        src = r["mathjax_src"]
        assert src and all(x.startswith(server) for x in src), f"{rel}: MathJax not served locally: {src}"


def test_figures_are_present_and_decoded(seen):
    with_fig = {rel: r for rel, r in seen.items() if r["has_figure"]}
    assert with_fig, "no page with a figure found"
    for rel, r in with_fig.items():
        assert r["widths"] and all(w > 0 for w in r["widths"]), f"{rel}: a figure failed to decode ({r['widths']})"
    assert (ROOT / "book" / "_build" / "screenshot.png").stat().st_size > 10_000


def test_figures_are_described_by_their_captions(seen):
    """Every figure image's alt text is words (its caption's first sentence, book/_ext/figure_alt.py),
    not its hashed file name."""
    bad = []
    for rel in (rel for rel, r in seen.items() if r["has_figure"]):
        for tag in re.findall(r"<img [^>]*_images/[^>]*>", (HTML / rel).read_text(encoding="utf-8")):
            alt = re.search(r'alt="([^"]*)"', tag)
            if not alt or len(alt.group(1).split()) < 3 or "_images/" in alt.group(1):
                bad.append(f"{rel}: {tag[:120]}")
    assert not bad, "figures without a description:\n" + "\n".join(bad[:10])


CJK_RUN = re.compile(r"[\u4e00-\u9fff]{2,}")


def test_chinese_terms_of_the_sources_are_searchable(server, browser):
    """The book quotes the sources' Chinese terms (逆序检验, 截尾, 子午圈 …): the search index
    holds each quoted run as a term, and the search page finds a chapter for one of them and for
    two characters inside it."""
    import json

    text = (HTML / "searchindex.js").read_text(encoding="utf-8")
    terms = json.loads(text[text.index("(") + 1:text.rindex(")")])["terms"]
    quoted = set()
    for src in list((ROOT / "book").rglob("*.ipynb")) + list((ROOT / "book").rglob("*.md")):
        if "_build" not in src.parts:
            quoted |= set(CJK_RUN.findall(src.read_text(encoding="utf-8")))
    assert len(quoted) >= 10, "the book quotes fewer Chinese terms than expected"
    missing = sorted(q for q in quoted if not any(q in t for t in terms))
    assert not missing, f"Chinese terms missing from the search index: {missing[:10]}"
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    # the whole term, and two characters inside it (book/_ext/cjk_search.py indexes the bigrams)
    for query in ("逆序检验", "逆序", "检验"):
        page.goto(f"{server}/search.html?q={query}", wait_until="load", timeout=60_000)
        page.wait_for_selector("ul.search li a", timeout=30_000)
        hits = page.eval_on_selector_all("ul.search li a", "els => els.map(e => e.getAttribute('href'))")
        assert any("05_gravity_time_series" in h for h in hits), (query, hits)
    page.close()


# ---------------------------------------------------------------- the execution report of another machine

def synthetic_record() -> dict:
    """An execution record as another machine may write it: a CPU name of 150 characters with a
    word of 80 and none, 16 cores and 1, two machines, run times from 0.4 s to 12345.6 s, failed
    and timed-out runs without a time, finishes in three time zones, every notebook of the book
    and 51 that it does not list (paths outside ``book/``, one name of 36 characters without a
    separator): 69 rows."""
    book = sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "book").rglob("*.ipynb")
                  if not {"_build", ".ipynb_checkpoints"} & set(p.parts))
    extra = ([f"book/an_unlisted_part_of_the_book/{i:02d}_a_notebook_that_the_table_of_contents_omits.ipynb"
              for i in range(40)]
             + [f"scratch/experiments_2027/{i:02d}_sensitivity_of_the_closed_loop_filter.ipynb" for i in range(10)]
             + ["notebooks/averylongnotebooknamewithnoseparator.ipynb"])
    machines = [{"cpu": "Intel(R) Xeon(R) CPU Max 9480 @ 1.90GHz (QEMU Virtual CPU version 2.5+) "
                        "AMD-EPYC-9654-96-Core-Processor-with-a-model-string-that-has-no-space-inside-it",
                 "cores": 16, "system": "Linux 6.8.0-1012-azure-fips-preempt-rt", "python": "3.12.11",
                 "numpy": "2.1.3", "numba": "0.61.2"},
                {"cpu": "QEMU Virtual CPU version 2.5+", "cores": 1, "system": "Linux 5.10.0-33-amd64",
                 "python": "3.11.2", "numpy": "1.26.4", "numba": "0.60.0"}]
    runs = [(12345.6, "ok"), (3600.0, "ok"), (0.4, "ok"), (987.6, "ok"), (None, "failed"), (None, "timeout"),
            (45.0, "ok")]
    finished = ["2027-12-31T23:59:59+00:00", "2028-01-01T05:29:58+05:30", "2027-12-31T18:59:57-05:00"]
    notebooks = {}
    for i, nb in enumerate(book + extra):
        seconds, outcome = runs[i % len(runs)]
        notebooks[nb] = {"seconds": seconds, "outcome": outcome, "finished": finished[i % 3],
                         "jobs": (1, 16)[i % 2], "machine": machines[i % 2]}
    return {"notebooks": notebooks}


def build_report_page(tmp: Path, record: dict) -> Path:
    """The execution report page built with the book's configuration, theme, extensions and CSS
    (``book/_config.yml``, ``book/_static``) from ``record``, beside a one-line page for each
    notebook of the book (so that its rows link as in the book); returns the HTML directory."""
    import json

    import yaml

    src = tmp / "book"
    src.mkdir(parents=True)
    for name in ("_ext", "_static", "_extra"):
        shutil.copytree(ROOT / "book" / name, src / name, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "book" / "references.bib", src / "references.bib")
    (tmp / "record.json").write_text(json.dumps(record), encoding="utf-8")
    config = yaml.safe_load((ROOT / "book" / "_config.yml").read_text(encoding="utf-8"))
    config["sphinx"]["config"]["execution_report"] = str(tmp / "record.json")
    (src / "_config.yml").write_text(yaml.safe_dump(config, allow_unicode=True), encoding="utf-8")
    docs = sorted(nb[len("book/"):-len(".ipynb")] for nb in record["notebooks"]
                  if nb.startswith("book/") and (ROOT / nb).exists())
    (src / "intro.md").write_text("# Report\n\nThe execution report of another machine.\n", encoding="utf-8")
    for doc in docs:
        (src / doc).parent.mkdir(parents=True, exist_ok=True)
        (src / f"{doc}.md").write_text(f"# {doc}\n\nA chapter.\n", encoding="utf-8")
    (src / "appendix").mkdir(exist_ok=True)
    shutil.copy(ROOT / "book" / "appendix" / "execution.md", src / "appendix" / "execution.md")
    toc = {"format": "jb-book", "root": "intro",
           "parts": [{"caption": "Chapters", "numbered": True,
                      "chapters": [{"file": d} for d in docs] + [{"file": "appendix/execution"}]}]}
    (src / "_toc.yml").write_text(yaml.safe_dump(toc), encoding="utf-8")
    r = subprocess.run([str(Path(sys.executable).parent / "jupyter-book"), "build", str(src), "--path-output",
                        str(tmp), "--warningiserror", "--nitpick", "--quiet"], capture_output=True, text=True,
                       cwd=tmp)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return tmp / "_build" / "html"


REPORT_JS = """() => {
  const t = document.querySelector('table.execution-report');
  const lines = e => { const r = document.createRange(); r.selectNodeContents(e); return r.getClientRects().length; };
  const words = [];
  t.querySelectorAll('p.execution-notebook').forEach(p => {
    const walk = document.createTreeWalker(p, NodeFilter.SHOW_TEXT);
    for (let n = walk.nextNode(); n; n = walk.nextNode()) words.push(n);
  });
  return {rows: t.tBodies[0].rows.length, links: t.querySelectorAll('p.execution-notebook a').length,
          broken: Array.from(t.querySelectorAll('.nowrap')).filter(e => lines(e) > 1).map(e => e.innerText)
                  .concat(words.filter(n => lines(n) > 1).map(n => n.textContent)),
          page: {client: document.documentElement.clientWidth, scroll: document.documentElement.scrollWidth},
          machines: Array.from(document.querySelectorAll('ul.execution-machines li')).map(li => {
            const b = li.getBoundingClientRect(); return {right: b.right, text: li.innerText.slice(0, 40)}; })};
}"""
"""The execution report's table: its rows and links; the run times, dates, times, outcomes, counts
and the words of paths (between two break opportunities) that stand on more than one line; the
page's width and overflow; where the machines' descriptions end."""


@pytest.fixture(scope="module")
def another_machine(tmp_path_factory):
    record = synthetic_record()
    return record, build_report_page(tmp_path_factory.mktemp("report"), record)


@pytest.mark.parametrize("width, font", [(1280, None), (390, None), (1280, WIDE_FONTS[0])])
def test_the_execution_report_of_another_machine_fits(another_machine, browser, width, font):
    """The execution report of a machine unlike the reference one (:func:`synthetic_record`),
    built with the book's theme and CSS: at 1280 px its table fits the content column and does not
    scroll (with the system's fonts and with :data:`WIDE_FONTS`), at 390 px (a phone) neither the page
    nor the column scrolls sideways (the table may scroll in its own box); at each no run time,
    date, time, outcome, count or word of a path is broken across lines, and no machine's
    description runs past the column."""
    record, html = another_machine
    n_book = sum(nb.startswith("book/") and (ROOT / nb).exists() for nb in record["notebooks"])
    with _serving(html) as url:
        page = browser.new_page(viewport={"width": width, "height": 900})
        page.goto(f"{url}/appendix/execution.html", wait_until="load", timeout=60_000)
        if font:
            page.add_style_tag(content=WIDE_FONTS_CSS)
        m = page.evaluate(WIDTH_JS, False)
        r = page.evaluate(REPORT_JS)
        page.close()
    assert r["rows"] == len(record["notebooks"]) >= 60 and r["links"] == n_book > 0, r
    problems = []
    if r["page"]["scroll"] > r["page"]["client"] + 1:
        problems.append(f"the page scrolls sideways ({r['page']['scroll']} > {r['page']['client']} px)")
    if m["column"]["scroll"] > m["column"]["client"] + 1:
        problems.append(f"the content column scrolls ({m['column']['scroll']} > {m['column']['client']} px)")
    for t in m["tables"] if width == 1280 else []:
        if t["right"] > m["right"] + 2 or t["wrapScroll"] > 2:
            problems.append(f"table {t['head']!r} {t['width']} px in a {m['column']['width']} px column "
                            f"(scrolls by {t['wrapScroll']} px)")
    problems += [f"broken across lines: {w!r}" for w in r["broken"][:5]]
    problems += [f"machine description past the column: {li['text']!r}" for li in r["machines"] if li["right"] > m["right"] + 2]
    assert not problems, f"at {width} px{f' in {font}' if font else ''}:\n" + "\n".join(problems)


# ---------------------------------------------------------------- what a reader sees, on every page

def test_every_page_reads_like_a_paper(seen):
    """Every page of the book, at 1280 px and at :data:`PHONE` px (:func:`reader_problems`): no
    number, status word or id of a table broken across lines, no raw Python output in an output
    area, no count written as a decimal, no code line over :data:`MAX_CODE` characters, and no page
    that scrolls sideways on a phone (a wide table scrolls inside its own box)."""
    problems = [f"{rel}: {p}" for rel, r in seen.items() for p in r["reader"]]
    assert not problems, "\n".join(problems)


PLANTED = {
    "clean": ("# A page that reads well\n\n"
              "| quantity | paper | reproduced | status | reason |\n|---|---|---|---|---|\n"
              + "".join(f"| attitude error per mGal, case {i} | 0.000110518712{i} | -1.5e-05 | not-reproduced | "
                        f"`chen2019-check-calibration-closed-forms-{i}` (4-3)-(4-8) differ |\n" for i in range(3))
              + "\nA range 1 .. 2, a quotation … and -0.05 are words of prose.\n"),
    "broken": ("# A number broken\n\n<table class=\"table\"><tbody><tr><td style=\"width: 3em; max-width: 3em; "
               "overflow-wrap: anywhere; word-break: break-all\">0.00011051871234</td><td>ok</td></tr>"
               "</tbody></table>\n"),
    "wide": "# A page wider than a phone\n\n<div style=\"width: 640px; height: 2em\">a box of 640 px</div>\n",
}
"""Markdown pages of the synthetic book: one that must pass, one with a number broken mid-token,
one wider than a phone."""


RAW_PLANTS = {
    "a dict or a set printed as Python writes it": "{'reproduced': 13}",
    "a numpy scalar's repr": "np.float64(0.25)",
    "a bare True/False": "True",
    "a Python power (**) outside code and maths": "x**2 + 1",
    "a truncation marker (...)": "[0.1, 0.2, ..., 0.9]",
    "a negative zero": "-0.0",
}
"""One stored output of each kind of :data:`RAW_OUTPUT`, in the planted notebook."""


def _planted_notebook():
    """A notebook page whose stored outputs are one of each kind of raw Python output
    (:data:`RAW_PLANTS`) and whose code has a line of 100 characters."""
    import nbformat

    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.cells = [nbformat.v4.new_markdown_cell("# Raw outputs")]
    for i, text in enumerate(RAW_PLANTS.values()):
        code = (f"counts = {{'reproduced': 13}}  # {'x' * 70}\n" if i == 0 else "") + f"print(value_{i})"
        nb.cells.append(nbformat.v4.new_code_cell(code, outputs=[
            nbformat.v4.new_output("stream", name="stdout", text=text + "\n")]))
    return nb


def build_planted_book(tmp: Path) -> Path:
    """A book of the pages of :data:`PLANTED` and :func:`_planted_notebook`, built with the book's
    configuration, extensions and CSS; returns the HTML directory."""
    import nbformat
    import yaml

    src = tmp / "book"
    src.mkdir(parents=True)
    for name in ("_ext", "_static", "_extra"):
        shutil.copytree(ROOT / "book" / name, src / name, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "book" / "references.bib", src / "references.bib")
    config = yaml.safe_load((ROOT / "book" / "_config.yml").read_text(encoding="utf-8"))
    (src / "_config.yml").write_text(yaml.safe_dump(config, allow_unicode=True), encoding="utf-8")
    for name, text in PLANTED.items():
        (src / f"{name}.md").write_text(text, encoding="utf-8")
    nbformat.write(_planted_notebook(), src / "raw.ipynb")
    toc = {"format": "jb-book", "root": "clean", "chapters": [{"file": f} for f in ("broken", "wide", "raw")]}
    (src / "_toc.yml").write_text(yaml.safe_dump(toc), encoding="utf-8")
    r = subprocess.run([str(Path(sys.executable).parent / "jupyter-book"), "build", str(src), "--path-output",
                        str(tmp), "--quiet"], capture_output=True, text=True, cwd=tmp)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return tmp / "_build" / "html"


def test_the_reader_checks_catch_what_they_look_for(tmp_path, browser):
    """:func:`reader_problems` on a synthetic book (:func:`build_planted_book`): the clean page
    passes (numbers, a status word and ids in a wide table, a range, an ellipsis and -0.05 in
    prose); a number broken mid-token, a page wider than a phone, each kind of raw output
    (:data:`RAW_PLANTS`) and a code line of 100 characters are each found."""
    html = build_planted_book(tmp_path)
    statuses = _statuses()
    found = {}
    with _serving(html) as url:
        page = browser.new_page(viewport={"width": 1280, "height": 900})
        for name in ("clean", "broken", "wide", "raw"):
            page.set_viewport_size({"width": 1280, "height": 900})
            page.goto(f"{url}/{name}.html", wait_until="load", timeout=60_000)
            page.evaluate(WAIT_MATH_JS)
            found[name] = reader_problems(read_as_a_reader(page, statuses))
        page.close()
    assert found["clean"] == [], found["clean"]
    assert any("broken across lines" in p and "0.00011051871234" in p for p in found["broken"]), found["broken"]
    assert any(f"at {PHONE} px the page scrolls sideways" in p for p in found["wide"]), found["wide"]
    for what in RAW_PLANTS:
        assert any(f"raw output, {what}" in p for p in found["raw"]), (what, found["raw"])
    assert any(f"over {MAX_CODE} characters" in p for p in found["raw"]), found["raw"]
