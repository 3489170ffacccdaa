"""The chen2019 family of SINS/GNSS error-state models (45-state and 36-state), with G, H and w.

Built on :mod:`replication.nav.errors` (the physics of F lives there, verified against a numerical
Jacobian of the mechanization); this module fixes the *state order* of chen2019, the noise
input G w of eq. (2-14) and the 6-dimensional position/velocity measurement with the lever-arm
correction of eq. (2-13).

45-state model, chen2019 eq. (2-14)/(2-15) and ch. 2 §4.1, state order exactly as listed in the
text ("系统状态向量 X 包括了 ...")::

     idx   block (``model.slices``)  chen2019 symbols                     units
     0-2   position                δL, δλ, δh                            rad, rad, m
     3-5   velocity                δV_E, δV_N, δV_U                      m/s
     6-8   attitude                φ_E, φ_N, φ_U                         rad
     9-11  accel_bias              b_x, b_y, b_z (∇_b)                   m/s²
    12-14  accel_markov            m_x, m_y, m_z (∇_m)                   m/s²
    15-17  accel_scale             K_ax, K_ay, K_az (δK_a)               1
    18-23  accel_misalignment      A_xy, A_yx, A_xz, A_zx, A_yz, A_zy    rad
    24-26  gyro_bias               b_x, b_y, b_z (ε_b)                   rad/s
    27-29  gyro_markov             m_x, m_y, m_z (ε_m)                   rad/s
    30-32  gyro_scale              K_gx, K_gy, K_gz (δK_g)               1
    33-38  gyro_misalignment       G_xy, G_yx, G_xz, G_zx, G_yz, G_zy    rad
    39-41  gravity                 g_x, g_y, g_z (δg, n-frame E, N, U)   m/s²
    42-44  lever_arm               l_x, l_y, l_z (P_SINS^b error)        m

The text lists "位置误差 L、h" — only two position errors; with them the list counts 44 states.
The 45 of the text (and the three position rows of Table 2-2's F1) need δλ: the longitude error
was lost from the list, and is restored here between δL and δh.

The six misalignment angles follow the text's order (xy, yx, xz, zx, yz, zy), which is also
the parameter order of :func:`replication.nav.sensors.misalignment_matrix` (eq. (2-8)).

Sign conventions (those of :mod:`replication.nav.errors`): navigation errors are computed minus
true, Ĉ_b^n = (I - φ×) C_b^n; a sensor-error state is the true error minus the compensated one.
With these, the gyro-error columns of the attitude rows carry -C_b^n where chen2019 eq. (2-15)
and Table 2-2 print +C_b^n (the report counts ε with the opposite sign; flipping the sign of
all twelve gyro-error states maps one convention onto the other and changes no observability
measure).

The 36-state model of chen2019's ref. [35] (Sun Hongxing et al. 2010, as chen2019 ch. 1 §3
describes it): 9 navigation errors; 24 IMU states — for the gyro drift and for the
accelerometer bias a random constant, a random walk and a first-order Gauss-Markov process
(3 × 3 states each), and random-constant scale-factor errors (3 + 3); 3 lever-arm states;
no misalignment states.  The report gives no order for it; this package uses the 45-state
model's order (accelerometer group before gyro group, lever arm last):

    position, velocity, attitude, accel_bias, accel_random_walk, accel_markov, accel_scale,
    gyro_bias, gyro_random_walk, gyro_markov, gyro_scale, lever_arm.

The sensor errors enter both models as one :class:`replication.nav.sensors.ImuErrors` of
standard deviations and intensities (``imu_sd``, eq. (2-10) per triad), the object
:func:`replication.nav.sensors.draw_imu_errors` draws a truth from.

Typical use::

    sd = ImuErrors(accel=TriadErrors(bias=..., markov_sigma=..., markov_tau=..., white_psd=...),
                   gyro=TriadErrors(bias=..., scale=..., misalignment=..., markov_tau=...))
    m = models.model_45(imu_sd=sd, position_sd=..., gravity_sigma=...)  # an errors.ErrorModel
    F = m.F(errors.NavPoint.from_trajectory(traj, k))                   # 45 × 45
    G, q, w = models.noise_input(m, C_bn)                               # G (45 × 15), PSDs, labels
    H = models.measurement_matrix(m, point, lever_arm_sins_b)           # 6 × 45, eq. (2-13)
    models.state_symbols(m)                                             # chen2019 symbols
    p = models.state_permutation(m, other)                              # x_other = x_m[p]

Because the returned object is a plain :class:`replication.nav.errors.ErrorModel`, it runs in
:func:`replication.nav.kalman.closed_loop` unchanged (blocks are found by name, not position).

The printed F of Table 2-2, checked against the derivation at the report's approximation level,
is :mod:`replication.papers.chen2019.table_2_2`.
"""

from __future__ import annotations

import math

import numpy as np

from replication.nav import earth
from replication.nav import errors as E
from replication.nav._validate import choice, components, numeric, positive
from replication.nav.rotations import rotvec_to_dcm, skew
from replication.nav.sensors import ImuErrors, TriadErrors

__all__ = ["CHEN2019_45_ORDER", "CHEN2019_36_ORDER", "MISALIGNMENT_COUPLINGS", "EXTEND_ORDER_45", "NAV_SYMBOLS",
           "model_45", "model_36",
           "state_symbols", "state_permutation", "reorder", "noise_input", "measurement_matrix",
           "measurement_function", "lever_arm_correction", "table_2_3_states"]


CHEN2019_45_ORDER = ("accel_bias", "accel_markov", "accel_scale", "accel_misalignment", "gyro_bias",
                     "gyro_markov", "gyro_scale", "gyro_misalignment", "gravity", "lever_arm")
"""Augmented blocks of the 45-state model in the order of the chen2019 text (after the 9 nav)."""


CHEN2019_36_ORDER = ("accel_bias", "accel_random_walk", "accel_markov", "accel_scale", "gyro_bias",
                     "gyro_random_walk", "gyro_markov", "gyro_scale", "lever_arm")
"""Augmented blocks of the 36-state model (ref. [35] of chen2019; order: this package's choice)."""


EXTEND_ORDER_45 = ("accel_bias", "gyro_bias", "accel_markov", "gyro_markov", "accel_scale", "gyro_scale",
                   "accel_misalignment", "gyro_misalignment", "gravity", "lever_arm")
"""Block order of ``errors.model_15(...).extend(accel_markov, gyro_markov, accel_scale, gyro_scale,
accel_misalignment, gyro_misalignment, gravity_shaping, lever_arm)`` — see :func:`state_permutation`."""

MISALIGNMENT_COUPLINGS = {"eq-2-8": "axis-angles", "table-2-2": "cross-axis"}
"""The report's two layouts of the misalignment parameters, by the printed part that shows each,
and the coupling of :data:`replication.nav.errors.MISALIGNMENT_COUPLINGS` that implements it: eq.
(2-8) lays out δC by axis angles, Table 2-2 prints F32/F33 and F52/F53 by cross-axis coefficients
(the two printed parts disagree)."""

NAV_SYMBOLS = ("δL", "δλ", "δh", "δV_E", "δV_N", "δV_U", "φ_E", "φ_N", "φ_U")


_MIS = ("xy", "yx", "xz", "zx", "yz", "zy")


_BLOCK_SYMBOLS = {
    "accel_bias": tuple(f"∇b_{a}" for a in "xyz"),
    "accel_random_walk": tuple(f"∇w_{a}" for a in "xyz"),
    "accel_markov": tuple(f"∇m_{a}" for a in "xyz"),
    "accel_scale": tuple(f"δK_a{a}" for a in "xyz"),
    "accel_misalignment": tuple(f"δA_{p}" for p in _MIS),
    "gyro_bias": tuple(f"εb_{a}" for a in "xyz"),
    "gyro_random_walk": tuple(f"εw_{a}" for a in "xyz"),
    "gyro_markov": tuple(f"εm_{a}" for a in "xyz"),
    "gyro_scale": tuple(f"δK_g{a}" for a in "xyz"),
    "gyro_misalignment": tuple(f"δG_{p}" for p in _MIS),
    "gravity": ("δg_E", "δg_N", "δg_U"),
    "lever_arm": ("l_x", "l_y", "l_z"),
}


# ----------------------------------------------------------------------------- helpers
_SECONDS = "{name} must be a positive number of seconds (or 1/s for beta), got {value}"


def _nonneg(x, name, n=3):
    a = components(x, name, n)
    if np.any(a < 0):
        raise ValueError(f"{name} must be finite and non-negative (SI units), got {a}")
    return a


def _nav_sd(position_sd, velocity_sd, attitude_sd, lat, h):
    ps = _nonneg(position_sd, "position_sd")
    earth.check_latitude(lat, polar_limit_deg=earth.POLAR_LIMIT_DEG, name="lat")
    earth.check_height(h, name="h")
    rm, rn = earth.radii(lat)
    return np.concatenate([[ps[1] / (rm + h), ps[0] / ((rn + h) * math.cos(lat)), ps[2]],
                           _nonneg(velocity_sd, "velocity_sd"), _nonneg(attitude_sd, "attitude_sd")])


_MARKOV_TAU = 3600.0
"""Correlation time [s] of both Gauss-Markov blocks when ``imu_sd`` is not given."""


def _imu_triads(imu_sd):
    """The (accel, gyro) triads of ``imu_sd``; ``None`` gives zero σ and τ = 3600 s."""
    if imu_sd is None:
        return TriadErrors(markov_tau=_MARKOV_TAU), TriadErrors(markov_tau=_MARKOV_TAU)
    if not isinstance(imu_sd, ImuErrors):
        raise TypeError("imu_sd must be a replication.nav.sensors.ImuErrors holding the standard deviations and "
                        f"intensities of the sensor errors (SI units), got {type(imu_sd).__name__} {imu_sd!r:.40}")
    for kind in ("accel", "gyro"):
        if not isinstance(getattr(imu_sd, kind), TriadErrors):
            raise TypeError(f"imu_sd.{kind} must be a replication.nav.sensors.TriadErrors, "
                            f"got {type(getattr(imu_sd, kind)).__name__}")
    return imu_sd.accel, imu_sd.gyro


def _triad_sd(triad, kind, model):
    """The fields of one triad of ``imu_sd`` checked as a model's σ and intensities (SI units)."""
    p = f"imu_sd.{kind}."
    tau = numeric(triad.markov_tau, p + "markov_tau")
    if tau.ndim == 0 and np.isposinf(tau):
        raise ValueError(f"{p}markov_tau is inf (TriadErrors' default: no Gauss-Markov process), but the {model} "
                         "model carries the Gauss-Markov states, with -1/τ in F whatever their σ: give their "
                         f"correlation time in seconds (without imu_sd the model uses {_MARKOV_TAU:g} s)")
    return dict(bias=_nonneg(triad.bias, p + "bias"), markov_sigma=_nonneg(triad.markov_sigma, p + "markov_sigma"),
                markov_tau=positive(triad.markov_tau, p + "markov_tau (correlation time)", _SECONDS),
                white_psd=_nonneg(triad.white_psd, p + "white_psd"), scale=_nonneg(triad.scale, p + "scale"),
                misalignment=_nonneg(triad.misalignment, p + "misalignment", 6))


# ----------------------------------------------------------------------------- the models
def model_45(*, imu_sd: ImuErrors | None = None, position_sd=(10.0, 10.0, 10.0), velocity_sd=0.1,
             attitude_sd=(1e-4, 1e-4, 1e-3), gravity_sigma=0.0, gravity_beta=1e-3, lever_arm_sd=0.0, lat=0.0,
             h=0.0, misalignment_coupling: str = "eq-2-8") -> E.ErrorModel:
    """The 45-state SINS/GNSS error model of chen2019 eqs. (2-14), (2-15) and Table 2-2.

    The states are in the text's order (see the module docstring; ``model.labels`` /
    :func:`state_symbols`).

    Dynamics: eq. (2-15) with every first-order term (:meth:`replication.nav.errors.ErrorModel.F`);
    random constants (eq. (2-5), (2-6), (2-9)): ẋ = 0; first-order Gauss-Markov biases (eq. (2-5)):
    ẋ = -x/τ + w with stationary σ (``markov_sigma`` of a triad; driving intensity 2σ²/τ —
    convert the report's "驱动白噪声方差强度" with
    :func:`replication.nav.sensors.markov_sigma_from_driving_psd`); gravity disturbance
    (eqs. (2-11), (2-12)): δġ = -β δg + n per ENU axis with stationary σ (``gravity_sigma``,
    ``gravity_beta`` = 1/correlation time); lever arm: constant, enters the measurement only
    (eq. (2-13), :func:`measurement_matrix`).

    The sensor errors come as one :class:`replication.nav.sensors.ImuErrors` of eq. (2-10), read
    as :func:`replication.nav.sensors.draw_imu_errors` reads it — the same object draws a truth
    and builds the filter that estimates it.  Per triad (``imu_sd.accel`` in m/s²-based units,
    ``imu_sd.gyro`` in rad/s-based units), field → block::

        bias          σ of the random constant           → accel_bias / gyro_bias (P0)
        markov_sigma  stationary σ of the Gauss-Markov   → accel_markov / gyro_markov (P0, Q)
        markov_tau    its correlation time τ [s]         → -1/τ on the block's diagonal of F
        white_psd     white-noise intensity              → ErrorModel.accel_psd / gyro_psd (Q)
        scale         σ of the scale-factor errors       → accel_scale / gyro_scale (P0)
        misalignment  σ of the six angles (xy, yx, xz, zx, yz, zy) → *_misalignment (P0)

    The Gauss-Markov states are in the model whatever their σ, and their -1/τ in F with them:
    ``markov_tau`` must be a finite time (``TriadErrors``' default ``inf``, "no process", is
    refused).

    All arguments are SI.  The standard deviations default to zero (no prior); set them (e.g.
    from chen2019 Table 4-41 with :mod:`replication.nav.units`) before running a filter.  A
    scalar σ applies to every axis of its block.

    Parameters
    ----------
    imu_sd : replication.nav.sensors.ImuErrors or None, optional
        Standard deviations and intensities of the accelerometer and gyro errors (table above):
        bias [m/s² | rad/s], markov_sigma [m/s² | rad/s], markov_tau [s], white_psd
        [(m/s²)²·s | (rad/s)²·s], scale [1], misalignment [rad].  Default ``None``: every σ and
        intensity zero, both correlation times 3600 s.
    position_sd : float or array_like, shape (3,)
        Initial position σ, east, north, up [m]; converted to (δL, δλ, δh) at (``lat``, ``h``).
    velocity_sd : float or array_like, shape (3,)
        Initial velocity σ, ENU [m/s].
    attitude_sd : float or array_like, shape (3,)
        Initial attitude σ, φ_E, φ_N, φ_U [rad].
    gravity_sigma : float or array_like, shape (3,)
        Stationary σ of the gravity disturbance per ENU axis [m/s²].
    gravity_beta : float
        Inverse correlation time β of the gravity disturbance [1/s].
    lever_arm_sd : float or array_like, shape (3,)
        σ of the lever-arm error, body frame [m].
    lat : float
        Latitude at which ``position_sd`` is converted [rad].
    h : float
        Height at which ``position_sd`` is converted [m].
    misalignment_coupling : str
        ``"eq-2-8"`` (the layout of δC in eq. (2-8), default) or ``"table-2-2"`` (the F32/F33,
        F52/F53 columns as Table 2-2 prints them) — the report's two printed parts disagree on it
        (:data:`MISALIGNMENT_COUPLINGS`).

    Returns
    -------
    model : replication.nav.errors.ErrorModel
        The model with 45 states, blocks in :data:`CHEN2019_45_ORDER`.

    Raises
    ------
    TypeError
        When ``imu_sd`` is not an ``ImuErrors`` (or a triad of it not a ``TriadErrors``).
    ValueError
        When a σ or intensity is negative or not finite, a correlation time is not a positive
        finite number of seconds, β is not positive, ``lat``/``h`` is out of range, or
        ``misalignment_coupling`` is not one of the two.
    """
    nav_sd = _nav_sd(position_sd, velocity_sd, attitude_sd, lat, h)
    acc, gyr = _imu_triads(imu_sd)
    a, g = _triad_sd(acc, "accel", "45-state"), _triad_sd(gyr, "gyro", "45-state")
    beta = positive(gravity_beta, "gravity_beta", _SECONDS)
    choice(misalignment_coupling, sorted(MISALIGNMENT_COUPLINGS), "misalignment_coupling")
    coupling = MISALIGNMENT_COUPLINGS[misalignment_coupling]
    blocks = (
        E.accel_bias(a["bias"]),
        E.accel_markov(a["markov_sigma"], a["markov_tau"]),
        E.accel_scale(a["scale"]),
        E.accel_misalignment(a["misalignment"], coupling=coupling),
        E.gyro_bias(g["bias"]),
        E.gyro_markov(g["markov_sigma"], g["markov_tau"]),
        E.gyro_scale(g["scale"]),
        E.gyro_misalignment(g["misalignment"], coupling=coupling),
        E.gravity_shaping(_nonneg(gravity_sigma, "gravity_sigma"), beta),
        E.lever_arm(_nonneg(lever_arm_sd, "lever_arm_sd")),
    )
    m = E.ErrorModel(blocks=blocks, accel_psd=a["white_psd"], gyro_psd=g["white_psd"], nav_sd=nav_sd)
    assert m.n == 45 and tuple(b.name for b in m.blocks) == CHEN2019_45_ORDER
    return m


def model_36(*, imu_sd: ImuErrors | None = None, accel_random_walk_psd=0.0, gyro_random_walk_psd=0.0,
             position_sd=(10.0, 10.0, 10.0), velocity_sd=0.1, attitude_sd=(1e-4, 1e-4, 1e-3), lever_arm_sd=0.0,
             lat=0.0, h=0.0) -> E.ErrorModel:
    """The 36-state model of chen2019's ref. [35] as the report describes it (ch. 1 §3).

    9 navigation + 24 IMU + 3 lever-arm states.  Interpretation (stated, the report prints no
    equations for it): for each triad a random-constant bias (``bias`` of the triad), a
    random-walk bias (state starts at zero, driven by ``*_random_walk_psd``) and a first-order
    Gauss-Markov process (``markov_sigma``, ``markov_tau``) — 18 states; random-constant
    scale-factor errors of gyros and accelerometers (``scale``) — 6 states; no misalignment and
    no gravity states.  The random constant and the random walk of one axis enter the dynamics
    through the same column (both are additive biases), so only their sum is observable from
    navigation errors; their separation rests on the priors and the noise model.

    The sensor errors come as in :func:`model_45` (one
    :class:`replication.nav.sensors.ImuErrors` of standard deviations and intensities, finite
    ``markov_tau``), with two differences: the model has no misalignment states, so a non-zero
    ``misalignment`` σ is refused rather than dropped; and the random walk of the bias, which
    eq. (2-10) and ``TriadErrors`` do not have (nor does the simulation of
    :func:`replication.nav.sensors.apply_imu_errors`), has its own two keywords.

    Units and conventions as :func:`model_45` (SI; a scalar σ applies to every axis).

    Parameters
    ----------
    imu_sd : replication.nav.sensors.ImuErrors or None, optional
        Standard deviations and intensities of the accelerometer and gyro errors: bias
        [m/s² | rad/s], markov_sigma [m/s² | rad/s], markov_tau [s], white_psd
        [(m/s²)²·s | (rad/s)²·s], scale [1]; misalignment must be zero.  Default ``None``: every
        σ and intensity zero, both correlation times 3600 s.
    accel_random_walk_psd : float or array_like, shape (3,)
        Intensity of the accelerometer bias random walk [(m/s²)²/s].
    gyro_random_walk_psd : float or array_like, shape (3,)
        Intensity of the gyro drift random walk [(rad/s)²/s].
    position_sd : float or array_like, shape (3,)
        Initial position σ, east, north, up [m]; converted to (δL, δλ, δh) at (``lat``, ``h``).
    velocity_sd : float or array_like, shape (3,)
        Initial velocity σ, ENU [m/s].
    attitude_sd : float or array_like, shape (3,)
        Initial attitude σ, φ_E, φ_N, φ_U [rad].
    lever_arm_sd : float or array_like, shape (3,)
        σ of the lever-arm error, body frame [m].
    lat : float
        Latitude at which ``position_sd`` is converted [rad].
    h : float
        Height at which ``position_sd`` is converted [m].

    Returns
    -------
    model : replication.nav.errors.ErrorModel
        The model with 36 states, blocks in :data:`CHEN2019_36_ORDER`.

    Raises
    ------
    TypeError
        When ``imu_sd`` is not an ``ImuErrors`` (or a triad of it not a ``TriadErrors``).
    ValueError
        When a σ or intensity is negative or not finite, a misalignment σ is not zero, a
        correlation time is not a positive finite number of seconds, or ``lat``/``h`` is out of
        range.
    """
    nav_sd = _nav_sd(position_sd, velocity_sd, attitude_sd, lat, h)
    acc, gyr = _imu_triads(imu_sd)
    a, g = _triad_sd(acc, "accel", "36-state"), _triad_sd(gyr, "gyro", "36-state")
    for kind, t in (("accel", a), ("gyro", g)):
        if np.any(t["misalignment"] != 0):
            raise ValueError(f"imu_sd.{kind}.misalignment must be zero for the 36-state model, which has no "
                             f"misalignment states (model_45 has them), got {t['misalignment']}")
    blocks = (
        E.accel_bias(a["bias"]),
        E.accel_bias(0.0, name="accel_random_walk",
                     random_walk_psd=_nonneg(accel_random_walk_psd, "accel_random_walk_psd")),
        E.accel_markov(a["markov_sigma"], a["markov_tau"]),
        E.accel_scale(a["scale"]),
        E.gyro_bias(g["bias"]),
        E.gyro_bias(0.0, name="gyro_random_walk", random_walk_psd=_nonneg(gyro_random_walk_psd, "gyro_random_walk_psd")),
        E.gyro_markov(g["markov_sigma"], g["markov_tau"]),
        E.gyro_scale(g["scale"]),
        E.lever_arm(_nonneg(lever_arm_sd, "lever_arm_sd")),
    )
    m = E.ErrorModel(blocks=blocks, accel_psd=a["white_psd"], gyro_psd=g["white_psd"], nav_sd=nav_sd)
    assert m.n == 36 and tuple(b.name for b in m.blocks) == CHEN2019_36_ORDER
    return m


# ----------------------------------------------------------------------------- labels and orders
def _check_model(model):
    if not isinstance(model, E.ErrorModel):
        raise TypeError(f"expected an replication.nav.errors.ErrorModel (e.g. models.model_45()), got {type(model).__name__}")
    return model


def state_symbols(model) -> list:
    """chen2019 symbols of the states of ``model`` (e.g. ``'φ_E'``, ``'δA_xy'``), in model order.

    Blocks with a name unknown to chen2019 keep the ``errors`` label (``block.component``).

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        Any error model.

    Returns
    -------
    symbols : list of str
        One symbol per state, length ``model.n``.

    Raises
    ------
    TypeError
        When ``model`` is not an ``ErrorModel``.
    """
    _check_model(model)
    out = list(NAV_SYMBOLS)
    for b in model.blocks:
        sym = _BLOCK_SYMBOLS.get(b.name)
        out += list(sym) if sym is not None and len(sym) == b.size else [f"{b.name}.{c}" for c in b.labels]
    return out


def table_2_3_states() -> list:
    """The 27 states of chen2019 Table 2-3 in the printed row order, as ``errors`` labels of the 45-state model.

    φ_E, φ_N, φ_U; ∇_x..z (constant accelerometer bias); δK_ax..az; δA_xy, δA_yx, δA_xz, δA_zx,
    δA_yz, δA_zy; ε_x..z (constant drift); δK_gx..gz; δG_(same order).

    Returns
    -------
    labels : list of str
        27 labels of :attr:`replication.nav.errors.ErrorModel.labels`, e.g. ``"phiE"``,
        ``"accel_bias.x"``, ``"gyro_misalignment.xy"``.
    """
    out = ["phiE", "phiN", "phiU"]
    out += [f"accel_bias.{a}" for a in "xyz"] + [f"accel_scale.{a}" for a in "xyz"]
    out += [f"accel_misalignment.{p}" for p in _MIS]
    out += [f"gyro_bias.{a}" for a in "xyz"] + [f"gyro_scale.{a}" for a in "xyz"]
    out += [f"gyro_misalignment.{p}" for p in _MIS]
    return out


def state_permutation(source, target) -> np.ndarray:
    """Index array ``p`` with ``x_target = x_source[p]`` for two models holding the same states.

    The states are matched by ``labels``, e.g. the chen2019 order of :func:`model_45` and the
    ``model_15(...).extend(...)`` order (:data:`EXTEND_ORDER_45`).  The inverse permutation is
    ``state_permutation(target, source)``; matrices transform as ``F_t = F_s[np.ix_(p, p)]``.

    Parameters
    ----------
    source : replication.nav.errors.ErrorModel
        The model whose state vector is indexed.
    target : replication.nav.errors.ErrorModel
        The model whose order is wanted.

    Returns
    -------
    p : ndarray of int, shape (n,)
        Positions in ``source`` of the states of ``target``.

    Raises
    ------
    TypeError
        When either argument is not an ``ErrorModel``.
    ValueError
        When the two models hold different states.
    """
    ls, lt = _check_model(source).labels, _check_model(target).labels
    if sorted(ls) != sorted(lt):
        missing = sorted(set(lt) - set(ls))
        extra = sorted(set(ls) - set(lt))
        raise ValueError(f"the two models hold different states: missing in source {missing}, extra {extra}")
    pos = {lab: i for i, lab in enumerate(ls)}
    return np.array([pos[lab] for lab in lt], dtype=int)


def reorder(model, block_order) -> E.ErrorModel:
    """The same model with its augmented blocks in ``block_order``; the 9 navigation states stay first.

    E.g. ``reorder(model_45(), EXTEND_ORDER_45)``.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The model to reorder.
    block_order : sequence of str
        A permutation of the model's block names.

    Returns
    -------
    model : replication.nav.errors.ErrorModel
        The reordered model (same blocks, noise intensities and navigation σ).

    Raises
    ------
    TypeError
        When ``model`` is not an ``ErrorModel``.
    ValueError
        When ``block_order`` is not a permutation of the block names.
    """
    _check_model(model)
    names = [b.name for b in model.blocks]
    block_order = list(block_order)
    if sorted(block_order) != sorted(names):
        raise ValueError(f"block_order must be a permutation of {names}, got {block_order}")
    return E.ErrorModel(blocks=tuple(model.block(nm) for nm in block_order), accel_psd=model.accel_psd,
                        gyro_psd=model.gyro_psd, nav_sd=model.nav_sd)


# ----------------------------------------------------------------------------- noise input G w
def noise_input(model, C_bn):
    """Noise distribution G and white-noise vector w of chen2019 eq. (2-14).

    ẋ = F x + G w, E[w(t) w(τ)ᵀ] = diag(q) δ(t - τ).  Columns of w, in this order (chen2019 Table
    2-2's w, extended): accelerometer white noise ω_a (3, enters δV̇ through C_b^n), gyro white noise
    ω_g (3, enters φ̇ through -C_b^n in this package's sign convention; +C_b^n as printed), then for
    every augmented block driven by noise (a Markov process ω_am/ω_gm, a random walk, the gravity
    shaping filter n of eq. (2-12)) its driving noise entering that block through I (a
    non-diagonal block intensity is factored by Cholesky, q = 1).  Satisfies
    ``G @ diag(q) @ G.T == model.G_Qc(C_bn)``.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model.
    C_bn : array_like, shape (3, 3)
        Attitude matrix C_b^n (body to ENU), a rotation matrix.

    Returns
    -------
    G : ndarray, shape (n, m)
        Noise distribution matrix (dimensionless: rotations and identities).
    q : ndarray, shape (m,)
        Intensities of the noise components, each in its state's unit squared per second
        ((m/s²)²/Hz for ω_a, (rad/s)²/Hz for ω_g; 1 for a Cholesky-factored block).
    labels : list of str
        Names of the m noise components (``"ω_ax"``, ``"w_gyro_markov.x"``, ...).

    Raises
    ------
    TypeError
        When ``model`` is not an ``ErrorModel``.
    ValueError
        When ``C_bn`` is not a 3×3 rotation matrix.
    """
    _check_model(model)
    C = np.asarray(C_bn, float)
    if C.shape != (3, 3) or not np.allclose(C @ C.T, np.eye(3), atol=1e-9):
        raise ValueError("C_bn must be a 3×3 rotation matrix (build it with rotations.euler_to_dcm)")
    cols, q, labels = [], [], []
    n = model.n

    def col_block(rows, M):
        g = np.zeros((n, M.shape[1]))
        g[rows, :] = M
        return g

    cols.append(col_block(slice(3, 6), C))
    q += list(model.accel_psd)
    labels += ["ω_ax", "ω_ay", "ω_az"]
    cols.append(col_block(slice(6, 9), -C))
    q += list(model.gyro_psd)
    labels += ["ω_gx", "ω_gy", "ω_gz"]
    for b in model.blocks:
        Q = np.asarray(b.noise_psd, float)
        if not np.any(Q) and not np.any(b.dynamics):
            continue
        s = model.slices[b.name]
        if np.allclose(Q, np.diag(np.diag(Q))):
            cols.append(col_block(s, np.eye(b.size)))
            q += list(np.diag(Q))
        else:
            cols.append(col_block(s, np.linalg.cholesky(Q)))
            q += [1.0] * b.size
        labels += [f"w_{b.name}.{c}" for c in b.labels]
    return np.hstack(cols), np.array(q), labels


# ----------------------------------------------------------------------------- measurement (2-13)
def _lever(lever_arm_b):
    l = numeric(lever_arm_b, "lever_arm_b")
    if l.shape != (3,) or not np.all(np.isfinite(l)):
        raise ValueError(f"lever_arm_b must be 3 finite body-frame components in metres, got {lever_arm_b!r}")
    return l


def _w_eb_b(point):
    return np.asarray(point.w_ib_b, float) - np.asarray(point.C_bn, float).T @ earth.earth_rate_enu(point.lat)


def lever_arm_correction(point, lever_arm_b):
    """chen2019 eq. (2-13): the corrections that carry the GNSS antenna position/velocity to the SINS centre.

    P_SINS = P_GNSS + C_b^n l, V_SINS = V_GNSS + C_b^n (ω_eb^b × l), with l = P_SINS^b the SINS
    centre in the body frame *seen from the antenna*.  The report prints the velocity term as
    C_b^n ω_nb^n P_SINS^b; the rigid-body rate of the lever arm seen from the Earth is
    ω_eb^b = ω_ib^b - C_n^b ω_ie^n (ω_nb^b differs from it by ω_en^b, ~1e-5 rad/s here).
    Note: :func:`replication.nav.sensors.gnss_measurements` takes the antenna seen from the SINS
    centre, i.e. ``lever_arm_b = -l``.

    Parameters
    ----------
    point : replication.nav.errors.NavPoint
        Evaluation point: latitude [rad], longitude [rad], height [m], v_enu [m/s], C_bn,
        f_b [m/s²], w_ib_b [rad/s].
    lever_arm_b : array_like, shape (3,)
        l, the SINS centre seen from the antenna, body frame [m].

    Returns
    -------
    dp_enu : ndarray, shape (3,)
        Position correction C_b^n l, ENU [m].
    dv_enu : ndarray, shape (3,)
        Velocity correction C_b^n (ω_eb^b × l), ENU [m/s].

    Raises
    ------
    ValueError
        When ``lever_arm_b`` is not three finite components.
    """
    l = _lever(lever_arm_b)
    C = np.asarray(point.C_bn, float)
    return C @ l, C @ np.cross(_w_eb_b(point), l)


def _pos_scale(point):
    rm, rn = earth.radii(point.lat)
    return rm + point.h, (rn + point.h) * math.cos(point.lat)


def measurement_matrix(model, point, lever_arm_b=(0.0, 0.0, 0.0)) -> np.ndarray:
    """H of the position/velocity measurement of chen2019 Table 2-2 with the lever-arm correction of eq. (2-13).

    ::

        z = [ (R_M+h)(L_INS - L_GNSS'), (R_N+h) cos L (λ_INS - λ_GNSS'), h_INS - h_GNSS',
              V_E,INS - V_E,GNSS', V_N,INS - V_N,GNSS', V_U,INS - V_U,GNSS' ]

    (metres north, east, up, then m/s ENU — the row order of the report's Z) where GNSS' is the
    GNSS fix carried to the SINS centre with the *estimated* lever arm l̂ and attitude Ĉ by
    eq. (2-13).  To first order (derivation in :func:`measurement_function`)::

        z_p = D δp + φ × (C l) + C δl,      z_v = δv + φ × u + C (ω_eb^b ×) δl,   u = C (ω_eb^b × l)

    with D δp = [(R_M+h) δL, (R_N+h) cos L δλ, δh] and the ENU vectors reordered to (N, E, U)
    in the position rows.  Gyro-error terms of ω̂_eb (size δω · l ≲ 1e-7 m/s) are neglected.
    The lever-arm columns are filled only when ``model`` has a ``lever_arm`` block.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (n states).
    point : replication.nav.errors.NavPoint
        Evaluation point: latitude [rad], longitude [rad], height [m], v_enu [m/s], C_bn,
        f_b [m/s²], w_ib_b [rad/s].
    lever_arm_b : array_like, shape (3,)
        l, the SINS centre seen from the antenna, body frame [m] (eq. (2-13)).

    Returns
    -------
    H : ndarray, shape (6, n)
        Measurement matrix; rows in m (N, E, U) and m/s (E, N, U) per unit of each state.

    Raises
    ------
    TypeError
        When ``model`` is not an ``ErrorModel``.
    ValueError
        When ``lever_arm_b`` is not three finite components.
    """
    _check_model(model)
    l = _lever(lever_arm_b)
    C = np.asarray(point.C_bn, float)
    H = np.zeros((6, model.n))
    a, b = _pos_scale(point)
    neu = [1, 0, 2]
    H[0, 0], H[1, 1], H[2, 2] = a, b, 1.0
    H[3:6, 3:6] = np.eye(3)
    Cl = C @ l
    w = _w_eb_b(point)
    u = C @ np.cross(w, l)
    H[0:3, 6:9] = (-skew(Cl))[neu]
    H[3:6, 6:9] = -skew(u)
    if any(bl.name == "lever_arm" for bl in model.blocks):
        s = model.slices["lever_arm"]
        H[0:3, s] = C[neu]
        H[3:6, s] = C @ skew(w)
    return H


def measurement_function(model, point, lever_arm_b, x) -> np.ndarray:
    """The *nonlinear* measurement z(x) of :func:`measurement_matrix` for an error state ``x``.

    Used to verify H by finite differences: the INS state is the truth of ``point`` perturbed by
    δL, δλ, δh, δv, Ĉ = exp(-φ×) C, the used lever arm is l̂ = l - δl; the GNSS fix is the true
    antenna (SINS centre minus C l, eq. (2-13)) without noise; the fix is carried to the SINS
    centre with Ĉ and l̂, differenced with the INS and scaled to metres.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (n states).
    point : replication.nav.errors.NavPoint
        Evaluation point: latitude [rad], longitude [rad], height [m], v_enu [m/s], C_bn,
        f_b [m/s²], w_ib_b [rad/s].
    lever_arm_b : array_like, shape (3,)
        l, the true SINS centre seen from the antenna, body frame [m].
    x : array_like, shape (n,)
        Error state in the model's layout and units (δL, δλ rad, δh m, δv m/s, φ rad, ...).

    Returns
    -------
    z : ndarray, shape (6,)
        Position differences north, east, up [m] and velocity differences east, north, up [m/s].

    Raises
    ------
    TypeError
        When ``model`` is not an ``ErrorModel``.
    ValueError
        When ``x`` does not have n components or ``lever_arm_b`` is not three finite components.
    """
    _check_model(model)
    x = np.asarray(x, float)
    if x.shape != (model.n,):
        raise ValueError(f"x must have {model.n} components")
    l = _lever(lever_arm_b)
    C = np.asarray(point.C_bn, float)
    Ch = rotvec_to_dcm(-x[6:9]) @ C
    lh = l.copy()
    if any(bl.name == "lever_arm" for bl in model.blocks):
        lh = l - x[model.slices["lever_arm"]]
    w = _w_eb_b(point)
    # GNSS antenna (truth): SINS centre minus C l ; velocity minus C (ω × l)
    p_ant_enu_offset = -C @ l
    v_ant = np.asarray(point.v_enu, float) - C @ np.cross(w, l)
    # carried back to the SINS centre with the estimates
    p_sins_offset = p_ant_enu_offset + Ch @ lh          # ENU metres relative to the true SINS centre
    v_sins = v_ant + Ch @ np.cross(w, lh)
    a, b = _pos_scale(point)
    rm, rn = earth.radii(point.lat)
    # INS position error in metres (the truth of the fix is at the true latitude; first order)
    dN = a * x[0] - p_sins_offset[1]
    dE = b * x[1] - p_sins_offset[0]
    dU = x[2] - p_sins_offset[2]
    dv = (np.asarray(point.v_enu, float) + x[3:6]) - v_sins
    return np.array([dN, dE, dU, *dv])
