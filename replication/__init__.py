"""Reproduction library for SINS/GNSS research (chen2019, fang2020, duan2023, an2021)."""

__version__ = "0.1.0"
