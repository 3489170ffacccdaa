"""Package metadata: the version and the public repository, read by the registry, the CLI and the
book (a leaf module: it imports nothing of the package)."""

import functools
from pathlib import Path

__version__ = "0.1.0"


@functools.lru_cache(maxsize=None)
def repository_url() -> str:
    """The public repository of the package: ``[project.urls] Repository`` of ``pyproject.toml``.

    Read from the ``pyproject.toml`` beside the package when it runs from a checkout (an editable
    install's metadata is a copy taken when it was installed), otherwise from the installed
    distribution's metadata.  The README, ``CITATION.cff``, the BibTeX of ``python -m replication
    cite`` and the book's repository button and ``[source]`` links all carry this address.

    Returns
    -------
    url : str
        The repository's web address.
    """
    pyproject = Path(__file__).resolve().parent.parent / "pyproject.toml"
    if pyproject.is_file():
        import tomllib

        project = tomllib.loads(pyproject.read_text(encoding="utf-8")).get("project", {})
        if project.get("name") == "replication" and project.get("urls", {}).get("Repository"):
            return str(project["urls"]["Repository"])
    from importlib import metadata

    try:
        for entry in metadata.metadata("replication").get_all("Project-URL") or []:
            label, _, url = entry.partition(",")
            if label.strip().lower() == "repository":
                return url.strip()
    except metadata.PackageNotFoundError:
        pass
    raise RuntimeError("no repository URL: pyproject.toml's [project.urls] Repository is missing and the "
                       "installed 'replication' distribution declares none; reinstall with `make env`")
