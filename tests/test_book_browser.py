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
the column itself does not scroll sideways (scrollWidth against clientWidth, measured).

Run after the book is built (``make html-strict``); ``make test`` does both. Every request the
pages make is recorded: any request that leaves the local server, or fails, is an error. A
screenshot of one chapter is kept in ``book/_build/screenshot.png``.
"""

from __future__ import annotations

import functools
import html as html_lib
import http.server
import os
import re
import shutil
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


@pytest.fixture(scope="module")
def server():
    if not (HTML / "index.html").exists():
        pytest.fail("the book is not built: run `make html-strict` (part of `make test`) first")
    handler = functools.partial(_QuietHandler, directory=str(HTML))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()


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
    """At 1280 px: the content column does not scroll sideways, and no table of the register, the
    status page, the execution report or a chapter is wider than it or scrolls inside it."""
    problems = []
    for rel in WIDTH_PAGES:
        m = seen[rel]["widths_measured"]
        if m["column"]["scroll"] > m["column"]["client"] + 1:
            problems.append(f"{rel}: the content column scrolls ({m['column']['scroll']} > {m['column']['client']} px)")
        for t in m["tables"]:
            if t["right"] > m["right"] + 2 or t["wrapScroll"] > 2:
                problems.append(f"{rel}: table {t['head']!r} {t['width']} px in a {m['column']['width']} px column "
                                f"(scrolls by {t['wrapScroll']} px)")
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
