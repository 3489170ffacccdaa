"""Print the book as one PDF for readers: the single-page HTML build, rendered offline in headless Chromium.

    python scripts/book_pdf.py [--html book/_build/singlehtml] [--out book/_build/pdf/book.pdf]

``make pdf`` builds the single-page HTML from the stored notebook outputs (execution off) and runs
this script.  The page is served from this machine; every request that would leave it is refused.
MathJax (served locally by sphinx-mathjax-offline) typesets every formula and every figure
decodes; then, before Chromium prints the page on A4:

* the module pages of the library reference (``book/appendix/api/*``) are left out: the chapter
  "Library reference" keeps its one-page overview and says where the module pages are, and every
  link into them (a function named in a chapter) leads to that object's source lines in the
  repository instead;
* every link to a file offered for download (a table's CSV or JSON sidecar, a benchmark record)
  leads to that file in the repository, ``<repository>/blob/<commit>/<path>``, at the commit the
  book is printed from (the one the ``[source]`` links name); no link points to this machine;
* a title page (title, authors and citation from ``CITATION.cff``, the package version, the date,
  the commit and the repository address) and a numbered contents (parts, chapters and their
  sections) open the book.

Chromium prints the book once with placeholder page numbers in the contents; the pages each
entry's heading landed on are read from that PDF's named destinations and written into the
contents, and Chromium prints the front matter alone (the title page and the contents) again, in
place of the first print's: the numbers take the same room as the placeholders and the book's
first chapter starts on a new page, so the front matter keeps its page count (checked) and no page
after it moves.  The page numbers are the ones in the page footers.  ``book/_static/print.css`` hides the navigation and fits tables and figures to the page.
Chinese text needs a CJK font (Debian's fonts-wqy-zenhei, ``make sysdeps``).
"""

from __future__ import annotations

import argparse
import datetime
import functools
import http.server
import logging
import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path
from urllib.parse import urlparse

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
HTML = ROOT / "book" / "_build" / "singlehtml"
OUT = ROOT / "book" / "_build" / "pdf" / "book.pdf"
CHROMIUM = os.environ.get("CHROMIUM", shutil.which("chromium") or "/usr/bin/chromium")
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync"]
API_DOCS = "appendix/api/"
"""The documents of the library reference's module pages (``book/appendix/api/*``), left out of the print."""
BRANCH = "main"
"""The repository's default branch: the links' reference when git cannot name the commit."""

READY_JS = """async () => {
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) await MathJax.startup.promise;
  await Promise.all(Array.from(document.images).map(i => i.complete ? null : new Promise(r => { i.onload = i.onerror = r; })));
  await document.fonts.ready;
  return {math: document.querySelectorAll('mjx-container').length, errors: document.querySelectorAll('mjx-merror').length,
          broken: Array.from(document.images).filter(i => i.naturalWidth === 0).map(i => i.getAttribute('src'))};
}"""
"""Resolves once MathJax has typeset the page, every image has loaded and the fonts are ready."""

PREPARE_JS = """(a) => {
  const art = document.querySelector('.bd-article') || document.body;
  const el = (tag, cls, text) => { const e = document.createElement(tag); if (cls) e.className = cls;
                                   if (text !== undefined) e.textContent = text; return e; };
  // 1. the module pages of the library reference leave; every id they held maps to the source
  const gone = new Map();
  for (const span of Array.from(document.querySelectorAll('span[id^="document-' + a.api + '"]'))) {
    const sec = span.nextElementSibling && span.nextElementSibling.tagName === 'SECTION' ? span.nextElementSibling : null;
    const mod = sec && sec.id.startsWith('module-') ? sec.id.slice(7) : null;
    const first = sec && sec.querySelector('a.reference.external .viewcode-link');
    const file = (mod && a.modules[mod]) ? a.blob + a.modules[mod]
               : first ? first.closest('a').href.split('#')[0] : a.tree + 'replication';
    gone.set(span.id, file);
    if (sec) {
      gone.set(sec.id, file);
      for (const e of sec.querySelectorAll('[id]')) {
        const src = e.tagName === 'DT' ? e.querySelector(':scope > a.reference.external') : null;
        gone.set(e.id, src ? src.href : file);
      }
      sec.remove();
    }
    span.remove();
  }
  const api = document.getElementById('document-' + a.api.replace(/\\/$/, ''));
  const apiHeading = api && api.nextElementSibling && api.nextElementSibling.querySelector('h1, h2');
  if (apiHeading) apiHeading.after(el('p', 'print-note', a.api_note));
  // 2. links: into the removed pages -> the source; downloads -> the repository; nothing to this machine
  const unwrap = x => { x.replaceWith(...x.childNodes); };
  let to_source = 0, to_repository = 0;
  const unlinked = [];
  const local = [];
  for (const x of Array.from(document.querySelectorAll('a[href]'))) {
    const u = new URL(x.href, location.href);
    if (u.origin !== location.origin) continue;
    if (u.pathname === location.pathname) {
      const id = decodeURIComponent(u.hash.slice(1));
      if (gone.has(id)) { x.href = gone.get(id); to_source++; }
      else if (!id || !document.getElementById(id)) { unlinked.push(x.getAttribute('href')); unwrap(x); }
      continue;
    }
    const rel = decodeURIComponent(u.pathname.replace(/^\\//, ''));
    if (a.downloads[rel]) { x.href = a.downloads[rel]; x.removeAttribute('download'); to_repository++; }
    else if (rel.startsWith('_images/')) { unlinked.push(x.getAttribute('href')); unwrap(x); }      // a figure linking to its own image
    else local.push(x.getAttribute('href'));
  }
  // 3. the title page, and the contents in place of the theme's printed list of chapters (no page numbers)
  document.querySelectorAll('#jb-print-docs-body').forEach(e => e.remove());
  const title = el('section', 'print-title');
  title.append(el('p', 'print-title-main', a.title), el('p', 'print-title-sub', a.subtitle),
               el('p', 'print-title-authors', a.authors));
  const facts = el('dl', 'print-title-facts');
  for (const [k, v, href] of a.facts) {
    const dd = el('dd');
    dd.textContent = v === href ? '' : v;
    if (href) { const l = el('a', '', href); l.href = href; dd.append(v === href ? '' : ' ', l); }
    facts.append(el('dt', '', k), dd);
  }
  title.append(facts, el('p', 'print-title-note', a.note));
  // 4. the contents: parts, chapters (the first heading of each document) and their sections
  const rows = [];
  const label = h => { const c = h.cloneNode(true); c.querySelectorAll('.headerlink, .section-number').forEach(e => e.remove());
                       c.querySelectorAll('[id]').forEach(e => e.removeAttribute('id'));
                       const f = document.createDocumentFragment(); f.append(...c.childNodes); return f; };
  const number = h => { const n = h.querySelector('.section-number'); return n ? n.textContent.trim() : ''; };
  const unique = id => id && document.querySelectorAll('[id="' + CSS.escape(id) + '"]').length === 1;
  const add = (level, h) => {   // the heading's section, or the heading under an id of its own if that id is not unique
    let id = h.parentElement.id;
    if (!unique(id)) { h.id = h.id || 'print-contents-' + rows.length; id = h.id; }
    rows.push({level, number: number(h), label: label(h), id});
  };
  const rootHeading = art.querySelector('h1');
  if (rootHeading) add(1, rootHeading);
  for (const span of document.querySelectorAll('.bd-article span[id^="document-"]')) {
    const sec = span.nextElementSibling;
    if (!sec || sec.tagName !== 'SECTION') continue;
    const doc = span.id.slice(9);
    if (a.parts[doc]) rows.push({level: 0, number: '', label: document.createTextNode(a.parts[doc]), id: null});
    const h = sec.querySelector(':scope > h1, :scope > h2');
    if (!h) continue;
    add(1, h);
    for (const sub of sec.querySelectorAll(':scope > section')) {
      const h3 = sub.querySelector(':scope > h2, :scope > h3');
      if (h3) add(2, h3);
    }
  }
  const contents = el('nav', 'print-contents');
  contents.append(el('h1', '', a.contents_title));
  const list = el('ol', 'print-contents-list');
  for (let i = 0; i < rows.length; i++) {
    const r = rows[i];
    const target = r.id || (rows[i + 1] && rows[i + 1].id);      // a part: the page of its first chapter
    const li = el('li', 'toc-l' + r.level);
    const link = el('a');
    link.href = '#' + target;
    link.dataset.target = target;
    const t = el('span', 'toc-title'); t.append(r.label.cloneNode(true));
    link.append(el('span', 'toc-num', r.number), t, el('span', 'toc-dots'), el('span', 'toc-page', a.placeholder));
    li.append(link);
    list.append(li);
  }
  contents.append(list);
  art.prepend(title, contents);
  const plain = r => {   // an entry's words, a formula as the text of its MathML
    const c = el('span'); c.append(r.label.cloneNode(true));
    c.querySelectorAll('mjx-container').forEach(m => {
      const mml = m.querySelector('mjx-assistive-mml'); m.replaceWith(mml ? mml.textContent : ''); });
    return c.textContent.replace(/\\s+/g, ' ').trim(); };
  return {removed: gone.size, to_source, to_repository, unlinked, local,
          rows: rows.map((r, i) => ({level: r.level, number: r.number, title: plain(r), target: r.id || rows[i + 1].id}))};
}"""
"""Leaves the module pages out (their ids mapped to the source), points every link at the
repository or at a place in the book, and prepends the title page and the contents with
placeholder page numbers; returns what it did, every contents entry's target id, and the local
links it could not place (there must be none)."""

FILL_JS = """(pages) => {
  let missing = [];
  for (const a of document.querySelectorAll('.print-contents a[data-target]')) {
    const p = pages[a.dataset.target];
    if (p === undefined) missing.push(a.dataset.target);
    a.querySelector('.toc-page').textContent = p === undefined ? '' : String(p);
  }
  return missing;
}"""
"""Writes each contents entry's page number; returns the targets that have none."""

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

PLACEHOLDER = "000"
"""The page number of a contents entry in the first print: as wide as any number the front matter's second print writes."""

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


def _git(*args: str) -> str:
    try:
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def repository_files() -> list[str]:
    """The files of the repository (``git ls-files``; every file under the root, less ``.git``,
    ``.venv`` and the build, when git is unavailable), as paths relative to the root."""
    listed = _git("ls-files")
    if listed:
        return listed.splitlines()
    skip = {".git", ".venv", "_build", "__pycache__"}
    return [p.relative_to(ROOT).as_posix() for p in ROOT.rglob("*") if p.is_file() and not skip & set(p.parts)]


def download_targets(html: Path, blob: str) -> dict[str, str]:
    """Where each file the single-page build offers for download lives in the repository.

    Sphinx copies a downloadable file to ``_downloads/<hash>/<name>``; its origin is the file of
    the repository with the same name and the same bytes.

    Parameters
    ----------
    html : Path
        The single-page build.
    blob : str
        ``<repository>/blob/<commit>/``, the prefix of a file's address in the repository.

    Returns
    -------
    dict of str to str
        ``_downloads/<hash>/<name>`` to ``<repository>/blob/<commit>/<path>``.
    """
    by_name: dict[str, list[str]] = {}
    for rel in repository_files():
        by_name.setdefault(rel.rsplit("/", 1)[-1], []).append(rel)
    out, unknown = {}, []
    for f in sorted((html / "_downloads").glob("*/*")):
        body = f.read_bytes()
        same = [r for r in by_name.get(f.name, []) if (ROOT / r).is_file() and (ROOT / r).read_bytes() == body]
        if same:
            out[f.relative_to(html).as_posix()] = blob + min(same, key=len)
        else:
            unknown.append(f.relative_to(html).as_posix())
    if unknown:
        raise SystemExit(f"book_pdf: {len(unknown)} downloadable files of the book are no file of the repository "
                         f"(untracked, or changed since the HTML was built; rebuild with `make pdf`): {unknown[:5]}")
    return out


def module_files() -> dict[str, str]:
    """``replication.x.y`` to its file's path in the repository, for every module of the package."""
    out = {}
    for p in sorted((ROOT / "replication").rglob("*.py")):
        rel = p.relative_to(ROOT)
        parts = list(rel.with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = rel.as_posix()
    return out


def front_matter(today: datetime.date) -> dict:
    """The title page's words: the book's title, the package's title, version and authors from
    ``CITATION.cff``, the date, the commit and the repository address, and the parts' captions
    from ``book/_toc.yml`` keyed by each part's first document."""
    import yaml

    from replication import __version__, repository_url

    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    config = yaml.safe_load((ROOT / "book" / "_config.yml").read_text(encoding="utf-8"))
    toc = yaml.safe_load((ROOT / "book" / "_toc.yml").read_text(encoding="utf-8"))
    if cff.get("version") != __version__:
        raise SystemExit(f"book_pdf: CITATION.cff says version {cff.get('version')}, the package {__version__}: "
                         "make them agree before printing")
    authors = "; ".join(a.get("name") or " ".join(filter(None, (a.get("given-names"), a.get("family-names"))))
                        for a in cff.get("authors", []))
    repo = repository_url().rstrip("/")
    sha = _git("rev-parse", "HEAD")
    dirty = bool(sha and _git("status", "--porcelain", "--untracked-files=no", "--", "replication", "book", "tables",
                              "data"))
    ref = sha or BRANCH
    built = f"{today.isoformat()}, from commit {sha[:12]}" + (" + local changes" if dirty else "") if sha \
        else f"{today.isoformat()}, outside a git clone (links lead to the branch {BRANCH})"
    cite = f"{authors} ({today.year}). {cff['title']}, version {__version__}."
    parts = {}
    for part in toc.get("parts", []):
        first = (part.get("chapters") or [{}])[0].get("file")
        if first and part.get("caption"):
            parts[first] = part["caption"]
    return dict(title=config["title"], subtitle=cff["title"], authors=authors, repo=repo, ref=ref, parts=parts,
                subject=f"{cff['title']}, version {__version__}, printed {built}",
                facts=[["Version", f"replication {__version__}", None], ["Printed", built, None],
                       ["Repository", repo, repo], ["Licence", "code MIT; the tables in tables/ CC-BY-4.0", None],
                       ["Cite as", cite, repo]])


def destination_pages(pdf: Path, ids: list[str]) -> dict[str, int]:
    """The page (1 = the first, as in the page footers) of each named destination ``ids`` of
    ``pdf`` that exists; Chromium names a destination after the id of the element a link targets."""
    from pypdf import PdfReader

    reader = PdfReader(pdf)
    named = reader.named_destinations
    out = {}
    for i in ids:
        d = named.get("/" + i) or named.get(i)
        if d is not None:
            out[i] = reader.get_destination_page_number(d) + 1
    return out


def _quiet_clone_counts() -> None:
    """pypdf's writer logs "Object count ... exceeds defined trailer size" for a clone it adds
    objects to: it counts the clone's own additions, not a defect."""
    quiet = logging.Filter()
    quiet.filter = lambda record: not record.getMessage().startswith("Object count")
    logging.getLogger("pypdf._writer").addFilter(quiet)


def splice_front(book: Path, front: Path, out: Path, n_front: int) -> None:
    """Write ``out``: the printed ``book`` with its first ``n_front`` pages (the title page and the
    contents with placeholder page numbers) replaced by the pages of ``front`` (the same front
    matter printed again with the numbers).  Each replaced page keeps its place in the page tree,
    so every named destination of ``book`` stays where it was; the links of the new contents name
    those destinations.

    Raises
    ------
    SystemExit
        When ``front`` does not hold ``n_front`` pages: the numbers would have moved the pages after it.
    """
    from pypdf import PdfReader, PdfWriter
    from pypdf.generic import NameObject

    new = PdfReader(front)
    if len(new.pages) != n_front:
        raise SystemExit(f"book_pdf: the front matter with page numbers took {len(new.pages)} pages, not "
                         f"{n_front}: the pages after it would move")
    _quiet_clone_counts()
    writer = PdfWriter(clone_from=str(book))
    for i in range(n_front):
        page = writer.pages[i]
        fresh = writer.add_page(new.pages[i])       # the new page's objects copied into the writer
        for key in ("/Contents", "/Resources", "/Annots"):
            if key in fresh:
                page[NameObject(key)] = fresh[key]
            elif key in page:
                del page[NameObject(key)]
        writer.remove_page(len(writer.pages) - 1)
    with open(out, "wb") as f:
        writer.write(f)


def add_outline(pdf: Path, rows: list[dict], pages: dict[str, int], front: dict) -> None:
    """Bookmark ``pdf`` as its contents read (parts, their chapters, the chapters' sections) and
    name its authors and version in its metadata; the viewer opens with the bookmarks shown.

    Chromium writes bookmarks only into a tagged PDF, whose structure tree would more than triple
    the file (26 MB against 7 for the book as printed in November 2026).

    Parameters
    ----------
    pdf : Path
        The printed book, rewritten in place.
    rows : list of dict
        The contents entries in order: ``level`` (0 a part, 1 a chapter, 2 a section), ``number``,
        ``title`` and ``target`` (the id whose page ``pages`` gives).
    pages : dict of str to int
        The page of each target, 1 being the first.
    front : dict
        :func:`front_matter`.
    """
    from pypdf import PdfReader, PdfWriter

    contents = 1                         # the page after the title page
    if not (PdfReader(pdf).pages[contents].extract_text() or "").lstrip().startswith("Contents"):
        raise SystemExit("book_pdf: the title page ran over one page: the contents do not start on page 2")
    _quiet_clone_counts()
    writer = PdfWriter(clone_from=str(pdf))
    writer.add_outline_item(title="Contents", page_number=contents)
    parents: dict[int, object] = {}
    for r in rows:
        level = r["level"]
        parent = parents.get(level - 1) if level else None
        item = writer.add_outline_item(title=f"{r['number']} {r['title']}".strip(), page_number=pages[r["target"]] - 1,
                                       parent=parent)
        parents = {k: v for k, v in parents.items() if k < level}
        parents[level] = item
    writer.add_metadata({"/Author": front["authors"], "/Subject": front["subject"]})
    writer.page_mode = "/UseOutlines"
    with open(pdf, "wb") as f:
        writer.write(f)


def build_pdf(html: Path = HTML, out: Path = OUT, timeout_ms: int = 300_000) -> dict:
    """Print the single-page build ``html`` to ``out`` (A4) for readers; return what was done:
    formulas typeset, links redirected, contents entries, prints, seconds, bytes."""
    html, out = Path(html), Path(out)
    if not Path(CHROMIUM).exists():
        raise SystemExit(f"book_pdf: Chromium not found at {CHROMIUM}: install Debian's 'chromium' (make sysdeps)")
    from playwright.sync_api import sync_playwright

    t0 = time.perf_counter()
    today = datetime.datetime.now(datetime.timezone.utc).date()
    front = front_matter(today)
    blob = f"{front['repo']}/blob/{front['ref']}/"
    args = dict(api=API_DOCS, modules=module_files(), blob=blob, tree=f"{front['repo']}/tree/{front['ref']}/",
                downloads=download_targets(html, blob), title=front["title"], subtitle=front["subtitle"],
                authors=front["authors"], facts=front["facts"], parts=front["parts"], contents_title="Contents",
                placeholder=PLACEHOLDER,
                note=("This print leaves out the module pages of the library reference (the HTML book has them): "
                      "a function named in the text links to its source lines in the repository, and every "
                      "downloadable table links to its file there, at the commit above."),
                api_note=("The module pages of this reference are not printed: they are part of the HTML book "
                          "(make html) and each module's docstrings. In this print, a function named in a chapter "
                          "links to its source lines in the repository."))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(html)))
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{httpd.server_address[1]}"
    external = []
    out.parent.mkdir(parents=True, exist_ok=True)
    first = out.with_name(out.stem + ".pass.pdf")
    front_pdf = out.with_name(out.stem + ".front.pdf")
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
            if ready["errors"] or ready["broken"]:
                raise SystemExit(f"book_pdf: {ready['errors']} MathJax errors, images that did not load: "
                                 f"{ready['broken'][:5]}")
            prep = page.evaluate(PREPARE_JS, args)
            if prep["local"]:
                raise SystemExit(f"book_pdf: {len(prep['local'])} links to files of the build that the repository "
                                 f"does not hold, which a PDF cannot carry: {prep['local'][:5]}")
            fit = page.evaluate(FIT_JS)
            targets = [r["target"] for r in prep["rows"]]
            options = dict(format="A4", print_background=True, display_header_footer=True,
                           header_template="<span></span>", footer_template=FOOTER, outline=False, tagged=False,
                           margin={"top": "14mm", "bottom": "16mm", "left": f"{MARGIN_MM}mm",
                                   "right": f"{MARGIN_MM}mm"})
            page.pdf(path=str(first), **options)
            pages = destination_pages(first, targets)
            missing = page.evaluate(FILL_JS, pages)
            if missing:
                raise SystemExit(f"book_pdf: no page found for contents entries {missing[:5]}")
            n_front = min(pages.values()) - 1          # the title page and the contents
            page.pdf(path=str(front_pdf), page_ranges=f"1-{n_front}", **options)
            browser.close()
    finally:
        httpd.shutdown()
    try:
        splice_front(first, front_pdf, out, n_front)
    finally:
        first.unlink(missing_ok=True)
        front_pdf.unlink(missing_ok=True)
    add_outline(out, prep["rows"], pages, front)
    return dict(formulas=ready["math"], external_refused=len(external), seconds=time.perf_counter() - t0,
                bytes=out.stat().st_size, shrunk=fit["shrunk"], strongest_zoom=fit["worst"], overrun=fit["left"],
                prints=2, contents=len(targets), to_source=prep["to_source"], to_repository=prep["to_repository"],
                unlinked=prep["unlinked"])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--html", type=Path, default=HTML, help="the single-page HTML build (default: %(default)s)")
    p.add_argument("--out", type=Path, default=OUT, help="the PDF to write (default: %(default)s)")
    a = p.parse_args(argv)
    r = build_pdf(a.html, a.out)
    from pypdf import PdfReader

    pages = len(PdfReader(a.out).pages)
    print(f"{a.out.relative_to(ROOT) if a.out.is_relative_to(ROOT) else a.out}: {pages} pages, {r['bytes'] / 1e6:.1f} MB, "
          f"{r['contents']} contents entries ({r['prints']} prints), {r['formulas']} formulas typeset, "
          f"{r['to_repository']} downloads and {r['to_source']} library links pointed at the repository, "
          f"{len(r['unlinked'])} links without a target unlinked {r['unlinked'][:3]}, {r['shrunk']} wide blocks shrunk "
          f"(to {r['strongest_zoom']:.2f} at most), {r['overrun']} wider than the page, "
          f"printed in {r['seconds']:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
