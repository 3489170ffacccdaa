"""The methods of the four source documents, one sub-package per paper, built on
:mod:`replication.nav` and never on each other (the chapters' figures in :mod:`.plots`).
"""
