"""Building the closed-loop filter's configuration from an error model and its measurements
(:func:`build_spec`, :class:`GnssRows`; the measurement kernels padded to :data:`MAX_MEASUREMENTS`)
and the runs' initial state (:func:`initial_batch_state`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import types
from numba.experimental.function_type import _get_wrapper_address
from numba.extending import typeof_impl

from replication.nav._validate import choice, finite_array, integer, numeric
from replication.nav.closedloop.bundles import BatchState, Spec
from replication.nav.closedloop.options import Options, resolve_options
from replication.nav.errors import ErrorModel
from replication.nav.measurements import (
    RESIDUAL_SIGNATURE,
    ROWS_SIGNATURE,
    Measurement,
    compile_residual,
    compile_rows,
)
from replication.nav.measurements.airdata import AirHeight, Airspeed
from replication.nav.measurements.gnss import GnssPosition, GnssVelocity
from replication.nav.measurements.specific_force import SpecificForce


@dataclass(frozen=True, eq=False)
class GnssRows:
    """The GNSS measurement rows of :func:`build_spec`: antenna position and velocity with the lever arm
    (chen2019 eqs. (3-17), (2-13)).

    Attributes
    ----------
    R_pos : (3, 3) array_like or None
        Diagonal position noise covariance (ENU, m²); ``None``: no position rows.
    R_vel : (3, 3) array_like or None
        Diagonal velocity noise covariance ((m/s)²); ``None``: no velocity rows.
    lever_arm_b : (3,) array_like
        Antenna lever arm in the body frame used by the filter, m.

    Raises
    ------
    ValueError
        For a covariance that is not 3×3, diagonal, positive and finite, or a lever arm that is
        not three finite numbers.
    """

    R_pos: object = None
    R_vel: object = None
    lever_arm_b: object = (0.0, 0.0, 0.0)

    def __post_init__(self):
        for name in ("R_pos", "R_vel"):
            M = getattr(self, name)
            if M is None:
                continue
            M = numeric(M, name)
            if M.shape != (3, 3) or np.any(M != np.diag(np.diag(M))) or not np.all(np.diag(M) > 0):
                raise ValueError(f"{name} must be a 3×3 diagonal matrix with positive variances (independent axes)")
            finite_array(M, name)
            object.__setattr__(self, name, M)
        object.__setattr__(self, "lever_arm_b", finite_array(self.lever_arm_b, "lever_arm_b", (3,)))


#: The most measurements of one filter: the kernel tuples of :class:`Spec` are padded to this length
#: with kernels that write no row, so one compiled loop serves every set of aids.
MAX_MEASUREMENTS = 8


@compile_rows
def _no_rows(par, data, ctx, c, enc, H, Rd, r):
    """No rows (the padding of the kernel tuples)."""
    return 0


@compile_residual
def _no_residual(par, data, ctx, c, z, m):
    """No residuals (the padding of the kernel tuples)."""
    return 0


class _Kernel:
    """A measurement kernel as the compiled loop receives it: its numba type and the address of its
    compiled code, found once.

    A compiled function passed to a compiled one as a first-class function is typed and its address
    looked up again at every call (about 50 µs a kernel, 0.8 ms for the sixteen kernels of
    :class:`Spec` at every chunk); this object carries both (numba's ``_numba_type_`` and wrapper
    address protocol), so passing it costs an attribute read.  The loop calls the kernel through
    its C wrapper: the same compiled code, the same numbers."""

    __slots__ = ("dispatcher", "_numba_type_", "_sig", "_addr")

    def __init__(self, dispatcher, sig):
        self.dispatcher = dispatcher
        self._sig = sig
        self._numba_type_ = types.FunctionType(sig)
        self._addr = _get_wrapper_address(dispatcher, sig)

    def signature(self):
        """The kernel's signature (numba's wrapper address protocol)."""
        return self._sig

    def __reduce__(self):
        # an address is valid in this process only: another one finds its own
        return _kernel, (self.dispatcher, self._sig)

    def __wrapper_address__(self):
        """The address of the kernel's compiled C wrapper (numba's wrapper address protocol)."""
        return self._addr


_KERNELS: dict = {}


def _kernel(dispatcher, sig) -> _Kernel:
    """The :class:`_Kernel` of ``dispatcher`` (made once per compiled function)."""
    key = (id(dispatcher), str(sig))
    k = _KERNELS.get(key)
    if k is None or k.dispatcher is not dispatcher:
        k = _KERNELS[key] = _Kernel(dispatcher, sig)
    return k


_SPEC_TYPES: dict = {}


@typeof_impl.register(Spec)
def _typeof_spec(val, c):
    """The numba type of a :class:`Spec`, found once per configuration.

    numba types a bundle of arrays and numbers from a fingerprint in compiled code; the kernels
    of a :class:`Spec` have none, so every call of the compiled loop would type its every field in
    Python (about 0.3 ms a chunk).  A configuration's fields are never replaced (a named tuple),
    so its type is kept, by identity, for the last configurations seen."""
    hit = _SPEC_TYPES.get(id(val))
    if hit is not None and hit[0] is val:
        return hit[1]
    ty = types.BaseTuple.from_types([typeof_impl(v, c) for v in val], Spec)
    if len(_SPEC_TYPES) >= 32:
        _SPEC_TYPES.clear()
    _SPEC_TYPES[id(val)] = (val, ty)
    return ty


#: Columns of ``ChunkInputs.obs`` when :func:`chunk_inputs` packs its ``gnss``, ``windows`` and ``aux``
#: arguments: GNSS position, GNSS velocity, the specific-force values, then the one-row aids of
#: ``build_spec(rows=...)``.
_PACKED_POS, _PACKED_VEL, _PACKED_SF, _PACKED_AUX = 0, 3, 6, 13

_ONE_ROW_AIDS = {"air_height": AirHeight, "airspeed": Airspeed}


def _packed_measurements(model, gnss: GnssRows, rows, sf_H):
    """The measurements of ``build_spec(gnss=..., rows=..., sf_H=...)`` and their columns in the
    ``obs`` that :func:`chunk_inputs` packs."""
    meas, offs = [], []
    if gnss.R_pos is not None:
        meas.append(GnssPosition(np.diag(gnss.R_pos)))
        offs.append(_PACKED_POS)
    if gnss.R_vel is not None:
        meas.append(GnssVelocity(np.diag(gnss.R_vel)))
        offs.append(_PACKED_VEL)
    meas.append(SpecificForce(sf_H))           # rows only at the epochs where a window ends
    offs.append(_PACKED_SF)
    for k, entry in enumerate(rows):
        if len(entry) != 3:
            raise ValueError(f"rows[{k}] must be (kind, state column or None, variance), got {entry!r}")
        kind, col, var = entry
        choice(kind, tuple(_ONE_ROW_AIDS), f"rows[{k}] kind")
        col = None if col is None else integer(col, f"rows[{k}] state column", 9)
        var = float(numeric(var, f"rows[{k}] variance"))
        if not (np.isfinite(var) and var > 0):
            raise ValueError(f"rows[{k}] variance must be positive and finite, got {var!r}")
        meas.append(_ONE_ROW_AIDS[kind](var, col))
        offs.append(_PACKED_AUX + k)
    if not (gnss.R_pos is not None or gnss.R_vel is not None or len(rows)):
        raise ValueError("use at least one measurement: GNSS position (GnssRows.R_pos), velocity (R_vel) or a kind of "
                         "rows")
    return tuple(meas), offs


def _measurement_spec(model, measurements, offsets):
    """The measurement fields of :class:`Spec`: the kernel tuples (padded), constants, columns, m_max."""
    measurements = tuple(measurements)
    if not 1 <= len(measurements) <= MAX_MEASUREMENTS:
        raise ValueError(f"use 1..{MAX_MEASUREMENTS} measurements, got {len(measurements)}")
    for k, mz in enumerate(measurements):
        if not isinstance(mz, Measurement) or type(mz).rows_kernel is None or type(mz).residual_kernel is None:
            raise TypeError(f"measurements[{k}] must be a replication.nav.measurements.Measurement with its two "
                            f"kernels, got {type(mz).__name__}")
    if offsets is None:
        offsets = np.cumsum([0] + [mz.width for mz in measurements])[:-1]
    pars = [np.asarray(mz.parameters(model), float).ravel() for mz in measurements]
    par = np.zeros((MAX_MEASUREMENTS, max([1] + [len(p) for p in pars])))
    for k, p in enumerate(pars):
        par[k, :len(p)] = p
    pad = MAX_MEASUREMENTS - len(measurements)
    off = np.zeros(MAX_MEASUREMENTS, np.int64)
    off[:len(offsets)] = offsets
    width = np.zeros(MAX_MEASUREMENTS, np.int64)
    width[:len(measurements)] = [mz.width for mz in measurements]
    # the kernels are class attributes (a compiled function read from an instance binds to it)
    rows = tuple(type(mz).rows_kernel for mz in measurements) + (_no_rows,) * pad
    residuals = tuple(type(mz).residual_kernel for mz in measurements) + (_no_residual,) * pad
    return (tuple(_kernel(f, ROWS_SIGNATURE) for f in rows), tuple(_kernel(f, RESIDUAL_SIGNATURE) for f in residuals),
            len(measurements), par, off, width, int(sum(mz.size for mz in measurements)))


def build_spec(model: ErrorModel, *, gnss: GnssRows | None = None, rows=(), vmode: int = 0, gains=(0.0, 0.0, 0.0),
               ar=None, sf_H=None, nees: bool = False, options: Options | None = None, measurements=None) -> Spec:
    """The filter's configuration for ``model``.

    The measurements, in the order of their rows: ``measurements`` (objects of
    :mod:`replication.nav.measurements`, their values in ``ChunkInputs.obs`` side by side in
    this order), or else the ones the other arguments name, in the layout :func:`chunk_inputs`
    packs: GNSS antenna position and velocity (chen2019 eqs. (3-17), (2-13)), the specific-force
    rows of chen2019 eq. (3-18) at the epochs where a window ends, then the one-row aids of ``rows``.

    Parameters
    ----------
    model : ErrorModel
        The error-state model (15 states or any extension, :mod:`replication.nav.errors`).
    gnss : GnssRows, optional
        The lever arm and, without ``measurements``, the GNSS position and velocity rows.
    vmode : int
        Vertical channel: 0 free, 1 held, 2 damped with ``gains`` (:mod:`replication.nav.strapdown`).
    gains : (3,) array_like
        Gains of the damped vertical channel.
    ar : tuple (T, Q) of (n, n) arrays, optional
        Discrete transition applied at the epochs flagged in ``ChunkInputs.ar_tick``.
    sf_H : (3, n - 9) array_like, optional
        Gravity columns of the specific-force rows (chen2019 eq. (3-18)).
    rows : sequence of (str, int or None, float)
        Further one-row aids (``"air_height"``, ``"airspeed"``): the kind, the error state its
        measurement error is modelled by (column of ``model``, or None) and the variance of its
        white noise (m², (m/s)²).  The k-th entry reads its measured values from column k of the
        ``aux`` of :func:`chunk_inputs`.
    nees : bool
        Compute the NEES against the truth of the inputs.
    options : Options, optional
        Its ``series_order`` (order of the Van Loan series for (Φ, Q_d)) and ``prior_covariance``
        (also propagate the covariance without measurements).
    measurements : sequence of Measurement, optional
        The aids (at most :data:`MAX_MEASUREMENTS`); replaces ``rows`` and the GNSS rows of ``gnss``.

    Returns
    -------
    Spec
        The configuration bundle of :func:`run`.
    """
    if not isinstance(model, ErrorModel):
        raise TypeError("model must be a replication.nav.errors.ErrorModel")
    gnss = GnssRows() if gnss is None else gnss
    if not isinstance(gnss, GnssRows):
        raise TypeError(f"gnss must be a closedloop.GnssRows, got {type(gnss).__name__}")
    opt = resolve_options(options)
    n = model.n
    if measurements is None:
        measurements, offsets = _packed_measurements(model, gnss, rows, sf_H)
    else:
        offsets = None
    kernels_rows, kernels_res, n_meas, par, off, width, m_max = _measurement_spec(model, measurements, offsets)
    series_order = opt.series_order
    lever = gnss.lever_arm_b
    finite_array(gains, "gains", (3,))
    choice(vmode, (0, 1, 2), "vmode", "{name} must be one of {allowed} (free, held, damped), got {value!r}")
    fconst, qc, tg, kd, bs, bz = model.kernel_encoding()
    dyn = np.array([i - 9 for i in range(9, n) if np.any(fconst[i, 9:] != 0)], dtype=np.int64)
    if ar is None:
        arT, arQ = np.eye(n), np.zeros((n, n))
    else:
        arT, arQ = (np.ascontiguousarray(a, dtype=float) for a in ar)
        if arT.shape != (n, n) or arQ.shape != (n, n):
            raise ValueError(f"ar = (T, Q) must be {n}×{n}")
    return Spec(fconst, qc, np.asarray(model.accel_psd, float), np.asarray(model.gyro_psd, float), tg, kd, bs, bz,
                int(series_order), dyn, kernels_rows, kernels_res, n_meas, par, off, width,
                np.ascontiguousarray(np.vstack([tg, kd, bs, bz]).reshape(4, -1), dtype=np.int64), int(m_max),
                lever.copy(), int(vmode), np.asarray(gains, float), arT, arQ, bool(opt.prior_covariance), bool(nees))


def initial_batch_state(st, q, lever0) -> BatchState:
    """Per-run state at the start of :func:`run`.

    Parameters
    ----------
    st : (R, 6) array_like
        Navigation states [L, λ, h, v_E, v_N, v_U] (rad, m, m/s).
    q : (R, 4) array_like
        Attitude quaternions q_b^n.
    lever0 : (3,) array_like
        Lever arm in use, body frame, m.

    Returns
    -------
    BatchState
    """
    st = np.ascontiguousarray(numeric(st, "st"))
    q = np.ascontiguousarray(numeric(q, "q"))
    if st.ndim != 2 or st.shape[1] != 6 or q.shape != (st.shape[0], 4):
        raise ValueError("st must be R×6 and q R×4")
    finite_array(st, "st"), finite_array(q, "q")
    lever0 = finite_array(lever0, "lever0", (3,))
    R = st.shape[0]
    return BatchState(st, st.copy(), q, None, np.tile(lever0, (R, 1)), np.zeros((R, 3)),
                      np.zeros((R, 3)), np.zeros((R, 3)), np.column_stack([st[:, 0], np.sin(st[:, 0]),
                                                                            np.cos(st[:, 0])]),
                      np.zeros(R), np.zeros((R, 3)), np.array([1], np.int64))


def _with_phat(bs: BatchState, n_aug: int) -> BatchState:
    return bs._replace(p_hat=np.zeros((bs.st.shape[0], n_aug))) if bs.p_hat is None else bs


def _split(bs: BatchState, sl) -> BatchState:
    """Views of the runs ``sl`` of a batch state (the flag is per group)."""
    return BatchState(*(v[sl] if k != "first" else v.copy() for k, v in zip(BatchState._fields, bs)))

