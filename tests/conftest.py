"""Test-wide settings: no progress bars in test output (replication.nav.parallel reads REPLICATION_PROGRESS),
and the ``stored`` marker on the modules that compute nothing numerical."""

import os

import pytest

os.environ["REPLICATION_PROGRESS"] = "0"

STORED = frozenset({
    "test_architecture.py",      # the import rules, read from the sources
    "test_audit.py",             # statuses planted in copies of the stored tables, refused by the index
    "test_book_ext.py",          # the book's Sphinx extensions on small projects
    "test_captions.py",          # captions against the text around their tables
    "test_citations.py",         # the reference-list sweep on transcribed lists
    "test_docstrings.py",        # numpydoc sections, read from the objects
    "test_execution_report.py",  # the notebook runner's record and its page
    "test_installed.py",         # a wheel of the clone, answering from its stored tables
    "test_inventory.py",         # the inventory of each print against the stored tables
    "test_print_edition.py",     # the landing page's link to the PDF
    "test_reproduction.py",      # the registry: comparisons, statuses, displays, exports and the command line
    "test_tex_exports.py",       # the stored .tex exports through pdflatex, against the stored CSVs
    "test_words.py",             # the counts the book's words state, recomputed from the stored tables
})
"""Test modules that read stored files, sources or tooling and run no numerical code path of the
package (no numpy loop, BLAS kernel, libm function or compiled kernel decides their outcome): they
carry the ``stored`` marker, and ``scripts/portability.py`` runs them once, natively, not again under
a perturbed numerical configuration, where they would repeat the same work to the same verdict."""


SCHEDULING = frozenset({
    "test_parallel.py",          # the same batch on threads, processes, Dask and in chunks, compared bit for bit
})
"""Test modules that run one computation on several executors or chunkings and compare the results
bit for bit within one configuration: a numerical configuration changes both sides alike, so the
verdict does not depend on it.  They carry the ``scheduling`` marker and run once, natively (the
kernels they schedule run under the perturbed configurations in the other tests and notebooks).

Two markers are set test by test, not by module: ``symbolic`` on the tests of the derivation
modules whose verdict is an identity of sympy's exact algebra (rationals and symbols, no floating
point: no numpy loop, BLAS kernel or libm function can change it), while the numerical cross-checks
beside them (finite differences, the navigation core, numeric substitution) stay unmarked and run
under the perturbed configuration too; and ``stored`` on the command-line tests of
test_error_classes.py, whose damaged files reach no numerical code path."""


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.path.name in STORED:
            item.add_marker(pytest.mark.stored)
        if item.path.name in SCHEDULING:
            item.add_marker(pytest.mark.scheduling)
