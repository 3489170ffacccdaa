"""Open the built book in headless Chromium, offline, and check what a reader sees.

Every page: loads without a request leaving the machine or failing, raises no JavaScript error,
leaves no raw ``$``/LaTeX outside rendered maths, shows no figure twice, and every local link
(with its ``#anchor``) resolves.  The status page, each part's page and one chapter per paper:
no table wider than the content column at 1280 px (the status and reason columns visible), the
status bars and the findings boxes present (a table with a status column must fit: data frames
printed by a notebook may scroll).  Math renders with the local MathJax; figures decode.
What a reader sees first: the landing page states the verdicts (the "In short" sentences of
``book/intro.md``) and links the repository; on the register, the status page, the execution
report and a few chapters with tables, no table or register is wider than the content column and
the column itself does not scroll sideways (scrollWidth against clientWidth, measured), with the
system's fonts and with the widest common ones (:data:`WIDE_FONTS`).  The execution report shows what the machine that ran the book recorded: it is also built from a
record of another machine (long CPU names, run times of hours, failed and timed-out runs, 1 and 16
cores, 69 notebooks) and measured at 1280 and 390 px, so that no check depends on who ran the book.

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

    def __init__(self, browser):
        self.page = browser.new_page(viewport={"width": 1280, "height": 900})
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
        """Load ``url`` until the network is idle; returns the page (the same tab every time)."""
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


CLIPPED_JS = """() => {
  const art = document.querySelector('.bd-article');
  const right = art.getBoundingClientRect().right;
  const withStatus = t => Array.from(t.querySelectorAll('th')).some(h => h.innerText.trim() === 'status');
  return Array.from(art.querySelectorAll('table')).filter(t => t.offsetParent !== null && withStatus(t)).map(t => {
    const box = t.parentElement;
    return {right: t.getBoundingClientRect().right, scroll: box.scrollWidth - box.clientWidth,
            head: (t.tHead ? t.tHead.innerText : '').slice(0, 60)};
  }).filter(t => t.right > right + 2 || t.scroll > 2);
}"""


FIGURES_JS = "Array.from(document.images).filter(i => i.src.includes('_images/')).map(i => i.naturalWidth)"
MATHJAX_SRC_JS = "Array.from(document.scripts).map(s => s.src).filter(s => s.includes('mathjax'))"
FINDINGS = ".admonition:has(.admonition-title:text('Findings of this chapter'))"
OVERVIEW = ["status.html"] + [f"{p}/index.html" for p in ("chen2019", "fang2020", "duan2023", "an2021")]

WIDTH_PAGES = ["register.html", "status.html", "appendix/execution.html", "appendix/exports.html",
               "foundations/01_earth_normal_gravity.html", "chen2019/02_imu_error_model_and_calibration.html",
               "fang2020/01_polar_grid_calibration.html", "an2021/01_gravity_to_attitude.html"]
"""Pages whose every table (registers, comparisons, the execution report) must fit at 1280 px."""

WIDTH_JS = """() => {
  const art = document.querySelector('.bd-article');
  const box = art.getBoundingClientRect();
  const tables = Array.from(art.querySelectorAll('table')).filter(t => t.offsetParent !== null
      && !t.closest('.cell_output .dataframe, .output .dataframe') && !t.classList.contains('dataframe'));
  return {column: {client: art.clientWidth, scroll: art.scrollWidth, width: Math.round(box.width)},
          tables: tables.map(t => {
            const wrap = t.parentElement;
            return {width: Math.round(t.getBoundingClientRect().width), right: t.getBoundingClientRect().right,
                    wrapScroll: wrap.scrollWidth - wrap.clientWidth,
                    head: (t.tHead ? t.tHead.innerText : t.innerText).replace(/\\s+/g, ' ').slice(0, 50)};
          }), right: box.right};
}"""
"""The content column's width and overflow, and each table's width and its container's overflow.
A data frame printed by a notebook (``.dataframe``) may scroll; a table of the book may not."""

WIDE_FONTS = ("DejaVu Sans", "DejaVu Sans Mono")
"""The widest of the common fonts of a Linux system (fontconfig's defaults on Debian), for text and
code.  The theme asks for the system's fonts, which differ from machine to machine: the tables are
measured with the system's fonts and again with these (:data:`WIDE_FONTS_CSS`), so that the verdict
does not depend on which fonts the machine that runs the check would choose."""

WIDE_FONTS_CSS = (f":root {{ --pst-font-family-base-system: '{WIDE_FONTS[0]}', sans-serif !important; "
                  f"--pst-font-family-monospace-system: '{WIDE_FONTS[1]}', monospace !important; }}")

LANDING = "intro.html"


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


@pytest.fixture(scope="module")
def seen(server, browser):
    """Every page visited once at 1280 px, with what each test below checks recorded."""
    wide = set(OVERVIEW + _chapter_of_each_paper())
    measured = set(WIDTH_PAGES)
    out = {}
    shot = False
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
                 has_math=r"\(" in text or "math notranslate" in text,
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
            r.update(clipped=page.evaluate(CLIPPED_JS), bars=page.locator(".status-bar").count(),
                     findings=page.locator(FINDINGS).count())
            if rel == "status.html":
                page.screenshot(path=str(ROOT / "book" / "_build" / "screenshot-status.png"), full_page=False)
        if rel in measured:
            r["widths_measured"] = page.evaluate(WIDTH_JS)
            page.add_style_tag(content=WIDE_FONTS_CSS)     # last: the page is left in these fonts
            r["widths_wide_fonts"] = page.evaluate(WIDTH_JS)
        if rel == LANDING:
            r["text"] = _normal(page.evaluate("() => document.querySelector('.bd-article').innerText"))
            r["repo_links"] = page.evaluate("""url => Array.from(document.querySelectorAll('a'))
                .filter(a => a.href.replace(/\\/$/, '') === url && a.getClientRects().length > 0).length""",
                                            _repository_url())
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


def test_no_table_or_register_is_wider_than_its_column(seen):
    """At 1280 px, with the system's fonts and with :data:`WIDE_FONTS`: the content column does not
    scroll sideways, and no table of the register, the status page, the execution report or a
    chapter is wider than it or scrolls inside it."""
    problems = []
    for rel, (key, fonts) in ((rel, k) for rel in WIDTH_PAGES
                              for k in (("widths_measured", ""), ("widths_wide_fonts", f" in {WIDE_FONTS[0]}"))):
        m = seen[rel][key]
        if m["column"]["scroll"] > m["column"]["client"] + 1:
            problems.append(f"{rel}{fonts}: the content column scrolls ({m['column']['scroll']} > {m['column']['client']} px)")
        for t in m["tables"]:
            if t["right"] > m["right"] + 2 or t["wrapScroll"] > 2:
                problems.append(f"{rel}{fonts}: table {t['head']!r} {t['width']} px in a {m['column']['width']} px "
                                f"column (scrolls by {t['wrapScroll']} px)")
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
    """The status page, the part pages and one chapter per paper: no table clipped or scrolled at
    1280 px; the status bars on the overview pages; a findings box at the top of each chapter."""
    problems = []
    for rel in OVERVIEW + _chapter_of_each_paper():
        r = seen[rel]
        if r["clipped"]:
            problems.append(f"{rel}: tables wider than the content column: {r['clipped'][:3]}")
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
        m = page.evaluate(WIDTH_JS)
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
