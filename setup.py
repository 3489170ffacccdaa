"""Build hook (the project is configured in pyproject.toml): a wheel built from a clone carries
what ``python -m replication status|show|cite`` and ``replication.load_table(s)`` read, so that an
installed package works from any directory.  The files are copied, laid out as in the clone, into
``replication/_data/`` of the wheel (``replication.registry.reproduction.PACKAGED_DATA``):

* ``tables/``            every exported table (.csv, .json, .md, .tex), status.csv, register.csv, datapackage.json
* ``data/artifacts.csv`` the list of reproducible artifacts
* ``data/sources.bib``   the BibTeX of the four source documents (``cite``)
* ``data/paper/``        the transcribed paper values the sidecars name as provenance

An editable install copies nothing: it reads the clone's live tables."""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
SHIPPED = ("tables", "data/artifacts.csv", "data/sources.bib", "data/paper")


class build_py_with_tables(build_py):
    def run(self):
        super().run()
        if getattr(self, "editable_mode", False):
            return
        dest = Path(self.build_lib) / "replication" / "_data"
        if dest.exists():
            shutil.rmtree(dest)
        for rel in SHIPPED:
            src = ROOT / rel
            if not src.exists():
                raise SystemExit(f"cannot build the package: {rel} is missing from {ROOT}")
            if src.is_dir():
                shutil.copytree(src, dest / rel, ignore=shutil.ignore_patterns(".*", "__pycache__"))
            else:
                (dest / rel).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(src, dest / rel)


setup(cmdclass={"build_py": build_py_with_tables})
