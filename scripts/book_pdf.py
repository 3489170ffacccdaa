"""Print the book as one PDF: the single-page HTML build, rendered offline in headless Chromium.

    python scripts/book_pdf.py [--html book/_build/singlehtml] [--out book/_build/pdf/book.pdf]

``make pdf`` builds the single-page HTML from the stored notebook outputs (execution off) and runs
this script.  The page is served from this machine; every request that would leave it is refused.
MathJax (served locally by sphinx-mathjax-offline) typesets every formula and every figure
decodes before Chromium prints the page on A4; ``book/_static/print.css`` hides the navigation and
fits tables and figures to the page.  Chinese text needs a CJK font (Debian's fonts-wqy-zenhei,
``make sysdeps``).
"""

from __future__ import annotations

import argparse
import functools
import http.server
import os
import shutil
import sys
import threading
import time
from pathlib import Path
from urllib.parse import urlparse

ROOT = Path(__file__).resolve().parent.parent
HTML = ROOT / "book" / "_build" / "singlehtml"
OUT = ROOT / "book" / "_build" / "pdf" / "book.pdf"
CHROMIUM = os.environ.get("CHROMIUM", shutil.which("chromium") or "/usr/bin/chromium")
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync"]

READY_JS = """async () => {
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) await MathJax.startup.promise;
  await Promise.all(Array.from(document.images).map(i => i.complete ? null : new Promise(r => { i.onload = i.onerror = r; })));
  await document.fonts.ready;
  return {math: document.querySelectorAll('mjx-container').length, errors: document.querySelectorAll('mjx-merror').length,
          broken: Array.from(document.images).filter(i => i.naturalWidth === 0).map(i => i.getAttribute('src'))};
}"""
"""Resolves once MathJax has typeset the page, every image has loaded and the fonts are ready."""

FIT_JS = """() => {
  document.querySelectorAll('details').forEach(d => { d.open = true; });
  const art = document.querySelector('.bd-article') || document.body;
  const artRight = art.getBoundingClientRect().right;
  const room = e => {  // the right edge of the content box of the element's container
    const p = e.parentElement, r = p.getBoundingClientRect(), cs = getComputedStyle(p);
    return Math.min(artRight, r.right - parseFloat(cs.paddingRight) - parseFloat(cs.borderRightWidth));
  };
  const blocks = () => Array.from(art.querySelectorAll('table, mjx-container[display="true"], pre'));
  const over = e => { const r = e.getBoundingClientRect(); return r.width > 0 && r.right > room(e) + 1; };
  let shrunk = new Set(), worst = 1;
  for (let pass = 0; pass < 3; pass++) {
    for (const e of blocks().filter(over)) {
      const r = e.getBoundingClientRect();
      const z = Math.max(0.3, (parseFloat(e.style.zoom) || 1) * (room(e) - r.left - 1) / r.width);
      e.style.zoom = z;
      shrunk.add(e); worst = Math.min(worst, z);
    }
  }
  const left = blocks().concat(Array.from(art.querySelectorAll('img'))).filter(over).length;
  return {width: art.getBoundingClientRect().width, shrunk: shrunk.size, worst, left};
}"""
"""Opens every dropdown (a PDF cannot), then shrinks (CSS zoom) each table, display formula or code block still wider than the printed
column after print.css has let its cells wrap; returns how many, the strongest zoom, and how many
elements still overrun the column."""

MARGIN_MM = 14
"""Left and right page margins."""

FOOTER = ('<div style="font-size:8px; width:100%; text-align:center; color:#555;">'
          '<span class="pageNumber"></span> / <span class="totalPages"></span></div>')


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


def _entry(html: Path) -> str:
    """The page that holds the book: ``index.html`` of the single-page build is a redirect to the
    root document; the largest page is the book."""
    pages = [p for p in html.glob("*.html") if p.name not in {"genindex.html", "search.html"}]
    if not pages:
        raise SystemExit(f"book_pdf: no HTML in {html}: build it first (make pdf does)")
    return max(pages, key=lambda p: p.stat().st_size).name


def build_pdf(html: Path = HTML, out: Path = OUT, timeout_ms: int = 300_000) -> dict:
    """Print the single-page build ``html`` to ``out`` (A4); return what was rendered: pages of
    HTML text, formulas typeset, MathJax errors, seconds."""
    html, out = Path(html), Path(out)
    if not Path(CHROMIUM).exists():
        raise SystemExit(f"book_pdf: Chromium not found at {CHROMIUM}: install Debian's 'chromium' (make sysdeps)")
    from playwright.sync_api import sync_playwright

    t0 = time.perf_counter()
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(html)))
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{httpd.server_address[1]}"
    external = []
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS)
            # the printed column: A4 less the margins, in CSS pixels (96 per inch)
            column = round((210 - 2 * MARGIN_MM) / 25.4 * 96)
            page = browser.new_page(viewport={"width": column, "height": 1400})

            def route(r):
                if urlparse(r.request.url).hostname in ("127.0.0.1", "localhost") or r.request.url.startswith("data:"):
                    r.continue_()
                else:
                    external.append(r.request.url)
                    r.abort()

            page.route("**/*", route)
            page.set_default_timeout(timeout_ms)
            page.goto(f"{base}/{_entry(html)}", wait_until="load", timeout=timeout_ms)
            page.emulate_media(media="print")
            ready = page.evaluate(READY_JS)
            fit = page.evaluate(FIT_JS)
            out.parent.mkdir(parents=True, exist_ok=True)
            page.pdf(path=str(out), format="A4", print_background=True, display_header_footer=True,
                     header_template="<span></span>", footer_template=FOOTER, outline=True, tagged=True,
                     margin={"top": "14mm", "bottom": "16mm", "left": f"{MARGIN_MM}mm", "right": f"{MARGIN_MM}mm"})
            browser.close()
    finally:
        httpd.shutdown()
    if ready["errors"] or ready["broken"]:
        raise SystemExit(f"book_pdf: {ready['errors']} MathJax errors, images that did not load: {ready['broken'][:5]}")
    return dict(formulas=ready["math"], external_refused=len(external), seconds=time.perf_counter() - t0,
                bytes=out.stat().st_size, shrunk=fit["shrunk"], strongest_zoom=fit["worst"], overrun=fit["left"])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--html", type=Path, default=HTML, help="the single-page HTML build (default: %(default)s)")
    p.add_argument("--out", type=Path, default=OUT, help="the PDF to write (default: %(default)s)")
    a = p.parse_args(argv)
    r = build_pdf(a.html, a.out)
    try:
        from pypdf import PdfReader
        pages = len(PdfReader(a.out).pages)
    except ImportError:
        pages = "?"
    print(f"{a.out.relative_to(ROOT) if a.out.is_relative_to(ROOT) else a.out}: {pages} pages, {r['bytes'] / 1e6:.1f} MB, "
          f"{r['formulas']} formulas typeset, {r['shrunk']} wide blocks shrunk (to {r['strongest_zoom']:.2f} at most), "
          f"{r['overrun']} wider than the page, printed in {r['seconds']:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
