"""The inputs of the closed-loop filter per chunk: :func:`chunk_inputs` (one chunk's
:class:`ChunkInputs`, the unused fields filled), :func:`array_inputs` (the callable of
:func:`run` over whole-flight arrays) and :func:`counting_inputs` (the same, advancing a progress bar).
"""

from __future__ import annotations

import numpy as np

from replication.nav.closedloop.bundles import ChunkInputs
from replication.nav.closedloop.spec import _PACKED_AUX, _PACKED_POS, _PACKED_SF, _PACKED_VEL
from replication.nav.measurements.specific_force import SpecificForce


def chunk_inputs(dt, dth, dvv, ep_step, *, gnss=None, vertical=None, windows=None, ar_tick=None, truth=None,
                 aux=None, n_aug: int = 0, obs=None) -> ChunkInputs:
    """The :class:`ChunkInputs` of one chunk of ``K`` IMU steps and ``E`` epochs for ``R`` runs,
    with the unused fields filled.

    Parameters
    ----------
    dt : (K,) array_like
        Step lengths, s.
    dth, dvv : (R, K, 3) array_like
        Gyro and accelerometer increments, rad and m/s.
    ep_step : (E,) array_like of int
        The step (0..K−1) after which each epoch falls.
    gnss : tuple (gpos, gvel), optional
        GNSS fixes [L, λ, h] (rad, m) and ENU velocities (m/s), each (R, E, 3) or None; zero when
        their rows are unused.
    vertical : tuple (h_ref, vu_ref), optional
        Vertical references of a held or damped vertical channel (m, m/s), each (K + 1,) or None;
        zero by default.
    windows : tuple, optional
        The specific-force windows (``sf_w`` (K,), ``sf_win`` (K,), ``sf_end`` (E,), ``sf_a``
        (windows × 3, m/s²), ``sf_R`` (windows × 3, (m/s²)²)); none by default.
    ar_tick : (E,) array_like of int, optional
        1 at the epochs of a discrete AR step; none by default.
    truth : tuple, optional
        (``truth_st`` (E × 6), ``truth_q`` (E × 4), ``truth_p`` (R × E × n_aug)) for the NEES.
    aux : (R, E, k) array_like, optional
        Measured values of the kinds of ``build_spec(rows=...)`` (m, m/s).
    n_aug : int
        Number of augmented states (the shape of the empty truth).
    obs : (R, E, D) array_like, optional
        The measured values of the measurements of ``build_spec(measurements=...)``, side by side;
        replaces the values of ``gnss``, ``windows`` and ``aux``, which are packed otherwise.

    Returns
    -------
    ChunkInputs
    """
    c = np.ascontiguousarray
    gpos, gvel = _pair(gnss, "gnss", "(gpos, gvel)")
    h_ref, vu_ref = _pair(vertical, "vertical", "(h_ref, vu_ref)")
    dth, dvv = c(dth, dtype=float), c(dvv, dtype=float)
    if dth.ndim != 3 or dth.shape[2] != 3 or dvv.shape != dth.shape:
        raise ValueError(f"dth and dvv must both be (runs, steps, 3) arrays, got {dth.shape} and {dvv.shape}")
    R, K_ = dth.shape[0], dth.shape[1]
    if np.shape(dt) != (K_,):
        raise ValueError(f"dt must hold one step length per step ({K_}), got shape {np.shape(dt)}")
    ep_step = np.asarray(ep_step, np.int64)
    if ep_step.ndim != 1 or np.any(ep_step < 0) or np.any(ep_step >= K_):
        raise ValueError(f"ep_step must be a 1-D array of steps in 0..{K_ - 1}")
    E_ = len(ep_step)
    sf_w, sf_win, sf_end, sf_a, sf_R = (windows if windows is not None else
                                        (np.zeros(K_), np.full(K_, -1, np.int64), np.full(E_, -1, np.int64),
                                         np.zeros((1, 3)), np.ones((1, 3))))
    truth_st, truth_q, truth_p = (truth if truth is not None else
                                  (np.zeros((E_, 6)), np.zeros((E_, 4)), np.zeros((R, E_, n_aug))))
    if obs is None:
        obs = np.zeros((R, E_, _PACKED_AUX + (0 if aux is None else np.shape(aux)[2])))
        if gpos is not None:
            obs[:, :, _PACKED_POS:_PACKED_POS + 3] = gpos
        if gvel is not None:
            obs[:, :, _PACKED_VEL:_PACKED_VEL + 3] = gvel
        obs[:, :, _PACKED_SF:_PACKED_AUX] = SpecificForce.epoch_values(sf_end, sf_a, sf_R)
        if aux is not None:
            obs[:, :, _PACKED_AUX:] = aux
    obs = c(obs, dtype=float)
    if obs.ndim != 3 or obs.shape[:2] != (R, E_):
        raise ValueError(f"obs must be (runs, epochs, columns) = ({R}, {E_}, ·), got {obs.shape}")
    return ChunkInputs(dt=c(dt, dtype=float), dth=dth, dvv=dvv,
                       h_ref=np.zeros(K_ + 1) if h_ref is None else c(h_ref, dtype=float),
                       vu_ref=np.zeros(K_ + 1) if vu_ref is None else c(vu_ref, dtype=float), ep_step=ep_step,
                       obs=obs, sf_w=c(sf_w), sf_win=c(sf_win), sf_end=c(sf_end, dtype=np.int64),
                       ar_tick=np.zeros(E_, np.int64) if ar_tick is None else c(ar_tick),
                       truth_st=c(truth_st), truth_q=c(truth_q), truth_p=c(truth_p))


def _pair(value, name, what):
    """``value`` as a pair (``None``: two ``None``), or a ``ValueError`` naming ``what``."""
    if value is None:
        return None, None
    if not isinstance(value, (tuple, list)) or len(value) != 2:
        raise ValueError(f"{name} must be a pair {what} (either may be None), got {type(value).__name__}")
    return value


def counting_inputs(inputs, bar):
    """``inputs`` of :func:`run` that advances a progress bar by the IMU steps of each chunk.

    A chunk counts the first time it is prepared (a replay for the smoother does not count it
    again), so the bar ends at ``n_steps``.

    Parameters
    ----------
    inputs : callable
        ``inputs(ci, k0, k1, eps, **kw)`` as :func:`run` takes it.
    bar : object
        A bar with ``update(k)`` (:func:`replication.nav.parallel.progress_bar`).

    Returns
    -------
    counted : callable
        The same inputs, advancing ``bar``.
    """
    if not callable(inputs):
        raise TypeError(f"inputs must be callable as inputs(ci, k0, k1, eps), got {type(inputs).__name__}")
    if not callable(getattr(bar, "update", None)):
        raise TypeError(f"bar must have an update(k) method (parallel.progress_bar), got {type(bar).__name__}")
    seen = set()

    def counted(ci, k0, k1, eps, **kw):
        if ci not in seen:
            seen.add(ci)
            bar.update(int(k1) - int(k0))
        return inputs(ci, k0, k1, eps, **kw)

    return counted


def array_inputs(t, dth, dvv, ep_samples, *, gnss=None, vertical=None, windows=None, ar_tick=None, truth=None,
                 aux=None, n_aug: int = 0, obs=None):
    """The ``inputs`` callable of :func:`run` for whole-flight arrays: each chunk's slices through
    :func:`chunk_inputs`.

    Parameters
    ----------
    t : (N + 1,) array_like
        Sample times, s.
    dth, dvv : (R, N, 3) array_like
        Increments of the ``R`` runs (rad, m/s).
    ep_samples : (E,) array_like of int
        Sample index of each epoch (as for :func:`run`).
    gnss : tuple (gpos, gvel), optional
        GNSS fixes and velocities, each (R, E, 3) or None (see :func:`chunk_inputs`).
    vertical : tuple (h_ref, vu_ref), optional
        Vertical references, each (N + 1,) or None.
    aux : (R, E, k) array_like, optional
        Measured values of the kinds of ``build_spec(rows=...)``, per run and epoch.
    windows : tuple, optional
        ``sf_w`` (N,), ``sf_win`` (N,), ``sf_end`` (E,), ``sf_a``, ``sf_R`` (per window, whole).
    ar_tick : (E,) array_like of int, optional
        AR epochs.
    truth : tuple, optional
        ``truth_st`` (E × 6), ``truth_q`` (E × 4), ``truth_p`` (R × E × n_aug).
    n_aug : int
        Number of augmented states.
    obs : (R, E, D) array_like, optional
        The measured values of ``build_spec(measurements=...)``, side by side (see :func:`chunk_inputs`).

    Returns
    -------
    callable
        ``inputs(chunk, k0, k1, epochs)`` → :class:`ChunkInputs`.
    """
    idx = np.asarray(ep_samples, np.int64)
    gpos, gvel = _pair(gnss, "gnss", "(gpos, gvel)")
    h_ref, vu_ref = _pair(vertical, "vertical", "(h_ref, vu_ref)")
    dt = np.diff(np.asarray(t, float))
    if np.ndim(dth) != 3 or np.shape(dth)[1:] != (len(dt), 3) or np.shape(dvv) != np.shape(dth):
        raise ValueError(f"dth and dvv must be (runs, {len(dt)}, 3): one increment per interval of t")
    for name, a in (("gpos", gpos), ("gvel", gvel), ("aux", aux), ("obs", obs)):
        if a is not None and (np.ndim(a) != 3 or np.shape(a)[:2] != (np.shape(dth)[0], len(idx))):
            raise ValueError(f"{name} must be (runs, epochs, ·) = ({np.shape(dth)[0]}, {len(idx)}, ·), got {np.shape(a)}")

    def inputs(ci, k0, k1, eps):
        j0 = int(np.searchsorted(idx, eps[0])) if len(eps) else 0
        j1 = j0 + len(eps)
        ep = slice(j0, j1)
        return chunk_inputs(dt[k0:k1], dth[:, k0:k1], dvv[:, k0:k1], np.asarray(eps, np.int64) - 1 - k0,
                            gnss=(None if gpos is None else gpos[:, ep], None if gvel is None else gvel[:, ep]),
                            vertical=(None if h_ref is None else h_ref[k0:k1 + 1],
                                      None if vu_ref is None else vu_ref[k0:k1 + 1]),
                            windows=None if windows is None else (windows[0][k0:k1], windows[1][k0:k1],
                                                                  windows[2][ep], windows[3], windows[4]),
                            ar_tick=None if ar_tick is None else ar_tick[ep],
                            truth=None if truth is None else (truth[0][ep], truth[1][ep], truth[2][:, ep]),
                            aux=None if aux is None else aux[:, ep], n_aug=n_aug,
                            obs=None if obs is None else obs[:, ep])
    return inputs

