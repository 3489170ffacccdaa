"""Open the built book in headless Chromium, offline: pages load, math renders, figures show.

Run after the book is built (``make html-strict``); ``make test`` does both. Every request the
pages make is recorded: any request that leaves the local server, or fails, is an error. A
screenshot of one chapter is kept in ``book/_build/screenshot.png``.
"""

from __future__ import annotations

import functools
import http.server
import os
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
        pytest.fail(f"Chromium not found at {CHROMIUM}: install Debian's 'chromium' (done by .ci/run)")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        b = pw.chromium.launch(
            executable_path=CHROMIUM,
            args=["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync"],
        )
        yield b
        b.close()


def _visit(browser, url: str):
    """Load ``url``; return (page, external requests, failed requests)."""
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    external, failed = [], []

    def on_request(req):
        host = urlparse(req.url).hostname
        if req.url.startswith(("data:", "blob:", "about:")):
            return
        if host not in ("127.0.0.1", "localhost"):
            external.append(req.url)

    page.on("request", on_request)
    page.on("requestfailed", lambda req: failed.append(f"{req.url} ({req.failure})"))
    page.on("response", lambda resp: failed.append(f"{resp.url} (HTTP {resp.status})") if resp.status >= 400 else None)
    page.goto(url, wait_until="networkidle", timeout=60_000)
    return page, external, failed


def test_every_page_loads_offline(server, browser):
    pages = _pages()
    assert len(pages) >= 5, "the book has too few pages"
    problems = []
    for p in pages:
        rel = p.relative_to(HTML).as_posix()
        page, external, failed = _visit(browser, f"{server}/{rel}")
        if external:
            problems.append(f"{rel}: requests leaving the machine: {external[:3]}")
        if failed:
            problems.append(f"{rel}: failed requests: {failed[:3]}")
        page.close()
    assert not problems, "\n".join(problems)


def test_math_is_rendered_by_the_local_mathjax(server, browser):
    with_math = [p for p in _pages() if r"\(" in p.read_text(encoding="utf-8") or "math notranslate" in p.read_text(encoding="utf-8")]
    assert with_math, "no page with math found"
    for p in with_math[:6]:
        rel = p.relative_to(HTML).as_posix()
        page, _, _ = _visit(browser, f"{server}/{rel}")
        page.wait_for_selector("mjx-container", timeout=30_000)
        n = page.locator("mjx-container").count()
        errors = page.locator("mjx-merror").count()
        src = page.evaluate("Array.from(document.scripts).map(s => s.src).filter(s => s.includes('mathjax'))")
        page.close()
        assert n > 0, f"{rel}: MathJax rendered nothing"
        assert errors == 0, f"{rel}: {errors} MathJax errors"
        assert src and all(s.startswith(server) for s in src), f"{rel}: MathJax not served locally: {src}"


def test_figures_are_present_and_decoded(server, browser):
    with_fig = [p for p in _pages() if "<img" in p.read_text(encoding="utf-8") and "_images/" in p.read_text(encoding="utf-8")]
    assert with_fig, "no page with a figure found"
    shot_taken = False
    for p in with_fig:
        rel = p.relative_to(HTML).as_posix()
        page, _, _ = _visit(browser, f"{server}/{rel}")
        widths = page.evaluate("Array.from(document.images).filter(i => i.src.includes('_images/')).map(i => i.naturalWidth)")
        if not shot_taken:
            page.screenshot(path=str(ROOT / "book" / "_build" / "screenshot.png"), full_page=False)
            shot_taken = True
        page.close()
        assert widths and all(w > 0 for w in widths), f"{rel}: a figure failed to decode ({widths})"
    assert (ROOT / "book" / "_build" / "screenshot.png").stat().st_size > 10_000
