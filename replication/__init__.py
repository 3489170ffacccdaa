"""Reproduction library for SINS/GNSS research (chen2019, fang2020, duan2023, an2021)."""

from replication._meta import __version__, repository_url
from replication.registry.reproduction import load_table, load_tables  # (the typed loaders of the exported tables)

__all__ = ["__version__", "load_table", "load_tables", "repository_url"]
