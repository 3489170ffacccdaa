# The two commands a user needs: `make book` and `make test` (see README.md).
SHELL := /bin/bash
PY_BOOT ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
export PYTHONHASHSEED := 0
# one BLAS thread: bit-reproducible linear algebra and no oversubscription on 2 cores
export OPENBLAS_NUM_THREADS := 1
export OMP_NUM_THREADS := 1
export MKL_NUM_THREADS := 1
export MPLBACKEND := module://matplotlib_inline.backend_inline
export REPLICATION_ROOT := $(CURDIR)
# no progress bars (replication.nav.parallel) in stored notebook outputs, nbval runs, tests and benchmarks
export REPLICATION_PROGRESS := 0
export PIP_DISABLE_PIP_VERSION_CHECK := 1
# bytecode is compiled on first import and kept in .venv (and replication/__pycache__, beside numba's
# cache): a PYTHONDONTWRITEBYTECODE inherited from the shell would make every notebook kernel and
# test process recompile every module it imports
unexport PYTHONDONTWRITEBYTECODE

NOTEBOOKS := $(shell find book -name '*.ipynb' -not -path '*/_build/*' -not -path '*/.ipynb_checkpoints/*' | sort)

.PHONY: help env sysdeps lint lock book notebooks notebook tables html test unit units unit-portable portability suite nbval \
        check-notebooks check-tables html-strict browser pdf pdf-test bench clean

help:
	@echo "make book   - create the environment if missing, re-execute every notebook, regenerate tables/, build book/_build/html"
	@echo "make test   - unit tests (native and on a perturbed numerical code path), strict nbval of every notebook"
	@echo "              re-executed under two perturbed numerical configurations, tables unchanged, strict book build,"
	@echo "              browser check, the PDF printed and checked (first installs Debian's chromium, fonts-wqy-zenhei and texlive-latex-base"
	@echo "              where the user may: make sysdeps)"
	@echo "make pdf    - the book as one PDF for readers, book/_build/pdf/book.pdf: title page, numbered contents with page numbers,"
	@echo "              every chapter without the library reference's module pages, links into the repository (printed by Chromium"
	@echo "              from the single-page HTML of the stored outputs); the next make html links it from the landing page"
	@echo "make nbval  - strict nbval of every notebook on this machine's native code path"
	@echo "make notebook NB=book/part/file.ipynb - execute one notebook in place"
	@echo "make lock   - recompile requirements.lock from requirements.in (needs network to PyPI)"
	@echo "make bench  - run the benchmark scripts, writing benchmarks/*.json (the pyins comparison uses python-ins, pinned in requirements.lock;"
	@echo "              BENCH_BEFORE=<commit> times the closed-loop filter of an earlier tree beside the current one)"

# ---------------------------------------------------------------- environment
env: $(STAMP)

# the locked packages are installed by uv (itself hash-pinned in requirements-tools.lock): the same
# hash-checked wheels as pip would install, in seconds instead of a minute; Python compiles the
# bytecode of the modules actually imported on first use (compiling all of every package up front
# cost 16 s of wall time and 31 s of CPU, for modules that are never imported)
$(STAMP): requirements.lock requirements-tools.lock pyproject.toml
	@test -x $(PY) || $(PY_BOOT) -m venv $(VENV)
	$(PY) -m pip install --quiet --require-hashes --no-deps -r requirements-tools.lock
	$(PY) -m uv pip install --quiet --python $(PY) --require-hashes --no-deps -r requirements.lock
	$(PY) -m pip install --quiet --no-deps --no-build-isolation -e . 2> >(grep -v "is ignored: it is neither a file nor a directory" >&2)
	@touch $(STAMP)

lock:
	$(PY_BOOT) -m pip install --quiet --require-hashes --no-deps -r requirements-tools.lock
	$(PY_BOOT) -m uv pip compile requirements.in --generate-hashes --python-version 3.11 \
	    --python-platform x86_64-manylinux_2_28 -o requirements.lock

# ---------------------------------------------------------------- book
book: env notebooks tables html

notebooks: env
	$(PY) scripts/run_notebooks.py $(NOTEBOOKS)

notebook: env
	@test -n "$(NB)" || { echo "usage: make notebook NB=book/part/file.ipynb"; exit 2; }
	$(PY) scripts/run_notebooks.py $(NB)

tables: env
	$(PY) -m replication index

html: env
	$(VENV)/bin/jupyter-book build book --path-output book --quiet

# ---------------------------------------------------------------- tests
test: sysdeps env lint check-notebooks suite tables check-tables

# the Debian packages the checks need (chromium, a CJK font, pdflatex): installed as root or with sudo
# without a password, otherwise a stop naming them (scripts/sysdeps.sh; .ci/run calls it too)
sysdeps:
	bash scripts/sysdeps.sh

unit: env
	$(PY) -m pytest -q tests -m "not browser"

# the unit tests natively and under a perturbed configuration, side by side on the two cores
units: env
	$(PY) scripts/portability.py units

# the unit tests once more on a perturbed numerical code path (scripts/portability.py says why), but for
# those that run no numerical code path, compare executors within one configuration or are identities of
# sympy's exact algebra (the `stored`, `scheduling` and `symbolic` markers, tests/conftest.py)
unit-portable: env
	$(PY) scripts/portability.py unit tests -m "not browser and not slow and not stored and not scheduling and not symbolic"

# the unit tests and the perturbed notebooks as one queue of jobs on every core this process may use, slowest first,
# with the strict book build and the browser check beside them (what `make test` runs)
suite: env
	$(PY) scripts/portability.py suite --book $(NOTEBOOKS)

# every notebook re-executed under two perturbed numerical configurations: strict nbval against
# the stored outputs, and tables/ unchanged
portability: env
	$(PY) scripts/portability.py nbval $(NOTEBOOKS)

nbval: env
	@test -n "$(NOTEBOOKS)" || { echo "no notebooks under book/"; exit 1; }
	$(PY) -m pytest -q -p no:cacheprovider --nbval --nbval-current-env $(NOTEBOOKS) \
	    --nbval-sanitize-with book/sanitize.cfg --nbval-cell-timeout=900 -o testpaths= -o addopts=

lint: env
	$(PY) -m ruff check replication tests scripts book/_ext

check-notebooks: env
	$(PY) scripts/check_notebooks.py $(NOTEBOOKS)

check-tables: tables
	@git diff --exit-code --stat -- tables/ || { echo "tables/ changed after re-running the notebooks: run 'make book' and commit"; exit 1; }
	@test -z "$$(git status --porcelain --untracked-files=all -- tables/)" || { git status --porcelain -- tables/; echo "untracked files in tables/: run 'make book' and commit"; exit 1; }

html-strict: env
	rm -rf book/_build
	$(VENV)/bin/jupyter-book build book --path-output book --warningiserror --nitpick --keep-going --quiet

browser: env
	$(PY) -m pytest -q tests/test_book_browser.py -m browser

# the book as one PDF for readers (book/_build/pdf/book.pdf): the single-page HTML build of the stored
# outputs (execution off), printed on A4 by headless Chromium, offline, maths typeset by the local MathJax;
# scripts/book_pdf.py leaves out the library reference's module pages, adds the title page and the
# contents (the front matter printed again fills in their page numbers) and points every link at the repository
pdf: env
	$(VENV)/bin/jupyter-book build book --path-output book --builder singlehtml --quiet
	$(PY) scripts/book_pdf.py

pdf-test: env
	$(PY) -m pytest -q tests/test_book_pdf.py -m browser

bench: env
	$(PY) scripts/benchmark_navigation.py
	$(PY) scripts/benchmark_polar.py
	$(PY) scripts/benchmark_chen2019_simulation.py
	$(PY) scripts/benchmark_closed_loop.py $(if $(BENCH_BEFORE),--before $(BENCH_BEFORE))
	$(PY) scripts/benchmark_parallel.py

clean:
	rm -rf book/_build .pytest_cache
