"""The options of the closed-loop filter: its numerics, records, smoother and threads (:class:`Options`,
:class:`Smoother`) and their defaults (:func:`resolve_options`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from replication.nav._validate import choice, integer


@dataclass(frozen=True)
class Smoother:
    """The fixed-interval smoother pass of :func:`run` (replaying the forward pass chunk by chunk).

    Attributes
    ----------
    form : {"mbf", "rts"}
        The backward recursion: the modified Bryson-Frazier form (:func:`mbf_chunk`, the default)
        or the Rauch-Tung-Striebel covariance form (:func:`rts_chunk`); the two give the same
        smoothed error and covariance (to rounding).  The MBF form inverts nothing and forms the
        O(n³) products only at the recorded epochs; it needs per epoch the lead's Φ, rows and
        gains and every run's innovations, so the forward pass keeps the innovations (runs ×
        epochs × rows) and the replay re-runs the lead alone.  The RTS form needs every run's
        estimates and replays the whole batch.
    covariance : bool
        Also compute the smoothed covariance P^s (default True).
    """

    form: str = "mbf"
    covariance: bool = True

    def __post_init__(self):
        choice(self.form, ("mbf", "rts"), "smoother form")
        if not isinstance(self.covariance, (bool, np.bool_)):
            raise TypeError(f"Smoother.covariance must be True or False, got {self.covariance!r}")


@dataclass(frozen=True)
class Options:
    """How the closed-loop filter runs: its numerics, what it records, its smoother, its threads.

    One bundle for :func:`build_spec` (which reads ``series_order`` and ``prior_covariance``),
    :func:`run` (which reads the rest) and the public entry points
    (:func:`replication.nav.kalman.closed_loop`,
    :func:`replication.papers.chen2019.simulation.run_batch`).  A field left ``None`` takes the
    default of the function it is given to (:meth:`resolved`): ``run_batch`` records every 20th
    epoch, :func:`run` every epoch.

    Attributes
    ----------
    record_every : int or None
        Record every ``record_every``-th epoch (the P's and the per-run records); run's default 1.
    chunk_epochs : int or None
        Epochs per chunk (memory of the gains and of the smoother's records), at least 2; run's
        default 2000.
    smoother : Smoother, bool or None
        The smoother pass (``True``: ``Smoother()``; ``None`` or ``False``: none).
    store_nav : bool or None
        Keep the IMU-rate solution; run's default False.
    store_P : bool or None
        Keep the covariance at the recorded epochs (``FilterResult.P``; its diagonal is always kept);
        run's default True.
    workers : int or None
        Threads for the runs that follow the lead (≥ 1; results do not depend on it); run's
        default 2.
    series_order : int or None
        Order of the Van Loan series for (Φ, Q_d); default 4.
    prior_covariance : bool or None
        Also propagate the covariance without measurements; default False.
    innovations : bool or None
        Also record, at the recorded epochs, the innovation covariance S = H P⁻ Hᵀ + R of the
        lead's rows and their number (``FilterResult.innovation_cov``, ``FilterResult.innovation_rows``;
        the innovations themselves are ``FilterResult.innov``); default False (no extra memory).
    """

    record_every: int | None = None
    chunk_epochs: int | None = None
    smoother: Smoother | bool | None = None
    store_nav: bool | None = None
    store_P: bool | None = None
    workers: int | None = None
    series_order: int | None = None
    prior_covariance: bool | None = None
    innovations: bool | None = None

    def __post_init__(self):
        sm = self.smoother
        if sm is True:
            object.__setattr__(self, "smoother", Smoother())
        elif sm is False:
            object.__setattr__(self, "smoother", None)
        elif sm is not None and not isinstance(sm, Smoother):
            raise TypeError(f"Options.smoother must be a closedloop.Smoother, True, False or None, got {sm!r}")
        for name, low in (("record_every", 1), ("chunk_epochs", 2), ("workers", 1), ("series_order", 1)):
            v = getattr(self, name)
            if v is not None:
                integer(v, f"Options.{name}", low)
        for name in ("store_nav", "store_P", "prior_covariance", "innovations"):
            v = getattr(self, name)
            if v is not None and not isinstance(v, (bool, np.bool_)):
                raise TypeError(f"Options.{name} must be True or False, got {v!r}")

    def resolved(self, **defaults) -> "Options":
        """These options with every field left ``None`` set from ``defaults``, then from :func:`run`'s.

        Parameters
        ----------
        **defaults : int or bool
            The caller's defaults, by field name.

        Returns
        -------
        Options
            Every field set.
        """
        unknown = set(defaults) - {f.name for f in fields(Options)}
        if unknown:
            raise TypeError(f"unknown Options fields {sorted(unknown)}")
        base = dict(_RUN_DEFAULTS, **defaults)
        return replace(self, **{f.name: base[f.name] for f in fields(Options)
                                if getattr(self, f.name) is None and f.name != "smoother"})


_RUN_DEFAULTS = dict(record_every=1, chunk_epochs=2000, store_nav=False, store_P=True, workers=2, series_order=4,
                     prior_covariance=False, innovations=False)


def resolve_options(value, defaults: dict | None = None, name: str = "options") -> Options:
    """``value`` (an :class:`Options` or ``None``) with its unset fields from ``defaults``, then :func:`run`'s.

    Parameters
    ----------
    value : Options or None
        The caller's options.
    defaults : dict, optional
        The entry point's defaults, by field name.
    name : str, optional
        The argument's name in the error message.

    Returns
    -------
    Options
        Every field set.
    """
    if value is None:
        value = Options()
    if not isinstance(value, Options):
        raise TypeError(f"{name} must be a closedloop.Options, got {type(value).__name__}")
    return value.resolved(**(defaults or {}))

