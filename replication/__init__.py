"""Reproduction library for SINS/GNSS research (chen2019, fang2020, duan2023, an2021)."""

__version__ = "0.1.0"

from .reproduction import load_table  # noqa: E402  (the typed loader of the exported tables)

__all__ = ["__version__", "load_table"]
