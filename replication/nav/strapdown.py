"""ENU strapdown mechanization (chen2019 eq. (3-2)).

Discrete algorithm (one update per IMU interval T, increments Δθ_k, Δv_k):

* attitude — exact rotation-vector update with the two-sample (previous + current sample)
  coning correction  φ_k = Δθ_k + Δθ_{k-1} × Δθ_k / 12,
  q_k = q(-ζ_k) ⊗ q_{k-1} ⊗ q(φ_k),  ζ_k = (ω_ie^n + ω_en^n) T at mid-interval;
* velocity — specific-force increment with rotation compensation ½ Δθ_k × Δv_k and two-sample
  sculling (Δθ_{k-1} × Δv_k + Δv_{k-1} × Δθ_k)/12, projected by (I - ζ×/2) C_b^n(k-1), plus
  [g^n - (2ω_ie^n + ω_en^n) × v^n] T at the extrapolated mid-interval state (chen2019 eq. (3-2));
* position — trapezoidal integration of L̇ = v_N/(R_M+h), λ̇ = v_E/((R_N+h) cos L), ḣ = v_U;
* vertical channel — ``"free"``, ``"hold"`` (height and vertical speed reset to a reference at
  every step, as the papers do) or ``"damped"`` (third-order loop on a reference height).

Earth quantities are those of :mod:`replication.nav.earth` (WGS-84 radii, Somigliana normal gravity
with height, Earth and transport rates), evaluated inside a compiled loop
(``replication.nav._kernels``).  Frames and angles: :mod:`replication.nav.rotations`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from replication.nav import _kernels as K
from replication.nav import earth
from replication.nav._validate import choice, matrix3, numeric, positive, rotation, vector3
from replication.nav.rotations import attitude_error, dcm_to_euler, dcm_to_quat, euler_to_dcm, quat_to_dcm, skew

__all__ = ["NavState", "NavSolution", "VerticalChannel", "vertical_channel", "mechanize", "navigation_rates",
           "vertical_damping_gains", "validate_time", "validate_increments", "VERTICAL_MODES"]

VERTICAL_MODES = {"free": 0, "hold": 1, "damped": 2}


@dataclass
class NavState:
    """Navigation state at one instant (the initial condition of :func:`mechanize`).

    The fields are checked on construction (:meth:`validate`); a field changed afterwards is
    checked again by :func:`mechanize` and by :meth:`validate`.

    Parameters
    ----------
    lat : float
        Geodetic latitude L (rad), inside ±``earth.POLAR_LIMIT_DEG``.
    lon : float
        Longitude λ (rad).
    h : float
        Ellipsoidal height (m), within :data:`replication.nav.earth.HEIGHT_RANGE`.
    v_enu : array_like, shape (3,)
        Velocity (m/s), East, North, Up.
    C_bn : array_like, shape (3, 3)
        Attitude, the direction cosine matrix C_b^n (body Right-Front-Up to ENU).
    """

    lat: float
    lon: float
    h: float
    v_enu: np.ndarray
    C_bn: np.ndarray

    def __post_init__(self):
        v = numeric(self.v_enu, "NavState.v_enu")
        if v.size != 3:
            raise ValueError(f"NavState.v_enu must have 3 components (East, North, Up), got shape {v.shape}")
        self.v_enu = v.reshape(3)
        self.C_bn = matrix3(numeric(self.C_bn, "NavState.C_bn"), "NavState.C_bn").reshape(3, 3)
        self.validate()

    def validate(self, *, name: str = "NavState", polar_limit_deg: float = earth.POLAR_LIMIT_DEG):
        """Check every field (also after a field was changed).

        Latitude within ±90° and outside the polar singularity, finite longitude, height within
        :data:`replication.nav.earth.HEIGHT_RANGE`, finite velocity below
        :data:`replication.nav.earth.SPEED_LIMIT`, C_bn a rotation matrix
        (``_validate.ORTHONORMAL_TOL``); the compiled mechanization checks nothing.

        Parameters
        ----------
        name : str, optional
            How the state is named in the messages (e.g. ``"initial"``).
        polar_limit_deg : float, optional
            Largest accepted |latitude| (degrees).

        Returns
        -------
        NavState
            The state itself.

        Raises
        ------
        TypeError, ValueError
            Naming the field at fault.
        """
        earth.check_latitude(self.lat, polar_limit_deg=polar_limit_deg, name=f"{name}.lat")
        earth.check_longitude(self.lon, name=f"{name}.lon")
        earth.check_height(self.h, name=f"{name}.h")
        earth.check_velocity(self.v_enu, name=f"{name}.v_enu")
        rotation(self.C_bn, f"{name}.C_bn")
        for field_ in ("lat", "lon", "h"):
            if np.ndim(getattr(self, field_)) != 0:
                raise ValueError(f"{name}.{field_} must be a single number, got shape {np.shape(getattr(self, field_))}")
        return self

    @classmethod
    def from_euler(cls, lat, lon, h, v_enu, heading, pitch, roll):
        """The state with its attitude given as Euler angles (:func:`replication.nav.rotations.euler_to_dcm`).

        Parameters
        ----------
        lat, lon : float
            Latitude and longitude (rad).
        h : float
            Ellipsoidal height (m).
        v_enu : array_like, shape (3,)
            Velocity (m/s), East, North, Up.
        heading, pitch, roll : float
            Heading ψ (clockwise from north), pitch θ, roll γ (rad).

        Returns
        -------
        NavState
        """
        return cls(lat, lon, h, v_enu, euler_to_dcm(heading, pitch, roll))

    def vector(self):
        """The position and velocity as one vector.

        Returns
        -------
        numpy.ndarray, shape (6,)
            [L (rad), λ (rad), h (m), v_E, v_N, v_U (m/s)].
        """
        return np.array([self.lat, self.lon, self.h, *self.v_enu])


@dataclass
class NavSolution:
    """Strapdown output at the N+1 sample instants (:func:`mechanize`).

    Parameters
    ----------
    t : numpy.ndarray, shape (N+1,)
        Sample times (s).
    lat, lon : numpy.ndarray, shape (N+1,)
        Latitude and longitude (rad).
    h : numpy.ndarray, shape (N+1,)
        Ellipsoidal height (m).
    v_enu : numpy.ndarray, shape (N+1, 3)
        Velocity (m/s), East, North, Up.
    q_bn : numpy.ndarray, shape (N+1, 4)
        Attitude quaternion q_b^n (scalar first); :attr:`C_bn` and :attr:`hpr` derive from it.
    """

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_enu: np.ndarray
    q_bn: np.ndarray

    @property
    def C_bn(self):
        """numpy.ndarray, shape (N+1, 3, 3): the attitude C_b^n."""
        return quat_to_dcm(self.q_bn)

    @property
    def hpr(self):
        """numpy.ndarray, shape (N+1, 3): heading, pitch, roll (rad)."""
        return self.hpr_at(slice(None))

    def hpr_at(self, index):
        """Heading, pitch, roll (rad) at the samples ``index`` alone: the rows ``index`` of :attr:`hpr`
        (C_b^n of the quaternion, :func:`~replication.nav.rotations.quat_to_dcm`, then
        :func:`~replication.nav.rotations.dcm_to_euler`), without converting the other samples.

        Parameters
        ----------
        index : int, slice or array_like of int
            Sample indices (numpy indexing of the N+1 samples).

        Returns
        -------
        numpy.ndarray, shape (..., 3)
            Heading, pitch, roll (rad) at those samples.
        """
        return np.stack(dcm_to_euler(quat_to_dcm(self.q_bn[index])), -1)

    @property
    def position(self):
        """numpy.ndarray, shape (N+1, 3): latitude (rad), longitude (rad), height (m)."""
        return np.stack([self.lat, self.lon, self.h], -1)

    def errors_against(self, truth):
        """Errors against a reference with the same samples.

        Parameters
        ----------
        truth : replication.nav.trajectory.Trajectory
            The true trajectory at the same N+1 samples.

        Returns
        -------
        dict of str to numpy.ndarray
            ``east``, ``north``, ``up`` (m, shape (N+1,)), ``v`` (m/s, ENU, shape (N+1, 3)) and
            ``phi`` (rad, shape (N+1, 3): the n-frame misalignment with Ĉ = exp(-φ×) C).
        """
        if len(truth.t) != len(self.t):
            raise ValueError(f"truth has {len(truth.t)} samples, the solution {len(self.t)}")
        rm, rn = earth.radii(truth.lat)
        return dict(
            north=(self.lat - truth.lat) * (rm + truth.h),
            east=(self.lon - truth.lon) * (rn + truth.h) * np.cos(truth.lat),
            up=self.h - truth.h,
            v=self.v_enu - truth.v_enu,
            phi=attitude_error(self.C_bn, truth.C_bn),
        )


def _all_finite(a) -> bool:
    """Whether every element of ``a`` is finite.  A NaN or an infinity makes the sum non-finite, so a
    finite sum settles it with one reduction; only a non-finite sum (also an overflow of large
    finite values) is looked at element by element."""
    with np.errstate(over="ignore", invalid="ignore"):
        total = a.sum()
    return bool(np.isfinite(total)) or bool(np.isfinite(a).all())


def _time_steps(t, n_increments, name):
    """:func:`validate_time` returning the checked times and their differences."""
    t = numeric(t, name)
    if t.ndim != 1 or len(t) < 2:
        raise ValueError(f"{name} must be a 1-D array of at least two sample times")
    if not _all_finite(t):
        raise ValueError(f"{name} contains NaN or infinite values")
    d = np.diff(t)
    if not d.min() > 0:
        k = int(np.argmax(d <= 0))
        raise ValueError(f"{name} must be strictly increasing: {name}[{k + 1}] = {t[k + 1]!r} follows "
                         f"{name}[{k}] = {t[k]!r}; sort the record or drop duplicated samples")
    if n_increments is not None and len(t) != n_increments + 1:
        raise ValueError(f"{name} has {len(t)} samples but there are {n_increments} increments: "
                         f"increments k = 1..N lie between samples, so len({name}) must be N + 1 = {n_increments + 1}")
    return t, d


def validate_time(t, n_increments: int | None = None, name: str = "t"):
    """Check a time vector: 1-D, finite, strictly increasing, matching the increments.

    Parameters
    ----------
    t : array_like, shape (N+1,)
        Sample times (s).
    n_increments : int or None, optional
        N, the number of increments between the samples (not checked when ``None``).
    name : str, optional
        The argument's name in the messages.

    Returns
    -------
    numpy.ndarray, shape (N+1,)
        ``t`` as a float array.

    Raises
    ------
    TypeError, ValueError
        Saying what is wrong and where (the first non-increasing sample).
    """
    return _time_steps(t, n_increments, name)[0]


def validate_increments(dtheta, dv):
    """Check IMU increments: two finite (N, 3) arrays of the same shape.

    Parameters
    ----------
    dtheta : array_like, shape (N, 3)
        Gyro increments Δθ (rad), body frame.
    dv : array_like, shape (N, 3)
        Accelerometer increments Δv (m/s), body frame.

    Returns
    -------
    dtheta, dv : numpy.ndarray, shape (N, 3)
        C-contiguous float arrays (the inputs themselves when they already are).

    Raises
    ------
    TypeError, ValueError
        For text, booleans or complex numbers, another shape, a NaN or an infinity, an angle
        increment beyond π rad or a velocity increment beyond ``earth.SPEED_LIMIT``.
    """
    dtheta = np.ascontiguousarray(numeric(dtheta, "dtheta"))
    dv = np.ascontiguousarray(numeric(dv, "dv"))
    if dtheta.ndim != 2 or dtheta.shape[1] != 3:
        raise ValueError(f"dtheta must have shape (N, 3), got {dtheta.shape}")
    if dv.shape != dtheta.shape:
        raise ValueError(f"dtheta and dv must have the same shape (one gyro and one accelerometer increment "
                         f"per interval), got {dtheta.shape} and {dv.shape}")
    if not (_all_finite(dtheta) and _all_finite(dv)):
        name, a = ("dtheta", dtheta) if not _all_finite(dtheta) else ("dv", dv)
        k = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
        raise ValueError(f"increments contain NaN or infinite values: {name}[{k[0]}, {k[1]}] = {a[k]!r}")
    if len(dtheta) and np.abs(dtheta).max() > np.pi:
        raise ValueError(f"dtheta must be angle increments of at most π rad per sample, got {np.abs(dtheta).max():.6g} "
                         "rad: a turn of more than half a revolution between two samples cannot be integrated (pass "
                         "increments in rad, not rates or degrees)")
    if len(dv) and np.abs(dv).max() > earth.SPEED_LIMIT:
        raise ValueError(f"dv must be velocity increments of at most {earth.SPEED_LIMIT:g} m/s per sample "
                         f"(earth.SPEED_LIMIT), got {np.abs(dv).max():.6g} m/s (pass increments in m/s, not a velocity "
                         "or another unit)")
    return dtheta, dv


def vertical_damping_gains(tau: float = 100.0, lat: float = 0.0, h: float = 0.0):
    """Third-order vertical-loop gains placing all three poles at -1/τ.

    With δḣ = δv_U - k1 δh, δv̇_U = (2γ/R) δh - k2 δh - k3 ∫δh, the characteristic polynomial is
    s³ + k1 s² + (k2 - 2γ/R) s + k3 = (s + 1/τ)³.

    Parameters
    ----------
    tau : float, optional
        Time constant τ of the loop (s).
    lat : float, optional
        Latitude (rad) where γ and R are evaluated.
    h : float, optional
        Height (m) where γ and R are evaluated.

    Returns
    -------
    numpy.ndarray, shape (3,)
        [k1 (1/s), k2 (1/s²), k3 (1/s³)].
    """
    tau = positive(tau, "tau", "the damping time constant {name} must be positive (seconds), got {value!r}")
    g = float(earth.normal_gravity(lat, h))
    rm, rn = earth.radii(lat)
    ws2 = 2 * g / float(np.sqrt(rm * rn) + h)
    if tau < 1e-100:                             # 1/τ³ beyond the float range
        raise ValueError(f"the damping time constant tau = {tau!r} s is too small: the gain 1/tau³ overflows; "
                         "tau is a time constant of the loop in seconds (tens to hundreds)")
    return np.array([3 / tau, 3 / tau**2 + ws2, 1 / tau**3])


def _ref(arr, n, name):
    a = np.ascontiguousarray(np.broadcast_to(numeric(arr, name), (n,)), dtype=float)
    if not _all_finite(a):
        raise ValueError(f"{name} contains NaN or infinite values")
    return a


@dataclass(frozen=True, eq=False)
class VerticalChannel:
    """The vertical channel of a mechanization: free, held to a reference, or damped on it.

    One description serves :func:`mechanize`, :func:`replication.nav.kalman.closed_loop` and
    :func:`replication.nav.kalman.monte_carlo`.  The references are checked against the number of
    samples where they are used.

    Attributes
    ----------
    mode : {"free", "hold", "damped"}
        Free; held (height and vertical speed set to ``h_ref`` and ``vu_ref`` after every step,
        the papers' height channel held to the true height); or damped (third-order loop on
        ``h_ref``, e.g. a barometric height, with all poles at -1/``damping_tau``,
        :func:`vertical_damping_gains`).
    h_ref : float or array_like, shape (N+1,), optional
        Reference height (m) at the samples; required by "hold" and "damped".
    vu_ref : float or array_like, shape (N+1,), optional
        Reference vertical speed (m/s) at the samples (default 0).
    damping_tau : float
        Time constant (s) of the damped loop, default 100.

    Raises
    ------
    ValueError
        For an unknown ``mode``, a mode other than "free" without ``h_ref``, or a damping time
        constant that is not positive and finite.
    """

    mode: str = "free"
    h_ref: object = None
    vu_ref: object = None
    damping_tau: float = 100.0

    def __post_init__(self):
        choice(self.mode, sorted(VERTICAL_MODES), "vertical mode")
        positive(self.damping_tau, "damping_tau", "{name} must be a positive finite time constant (s), got {value!r}")
        if self.mode != "free" and self.h_ref is None:
            raise ValueError(f"the {self.mode!r} vertical channel needs h_ref (reference heights at the N+1 samples): "
                             f"VerticalChannel({self.mode!r}, h_ref=...)")

    @property
    def code(self) -> int:
        """The mode's code in the compiled loops (``VERTICAL_MODES``)."""
        return VERTICAL_MODES[self.mode]

    def gains(self, lat: float, h: float) -> np.ndarray:
        """The loop gains at (``lat``, ``h``): :func:`vertical_damping_gains` when damped, else zeros.

        Parameters
        ----------
        lat : float
            Latitude (rad).
        h : float
            Height (m).

        Returns
        -------
        numpy.ndarray, shape (3,)
            [k1 (1/s), k2 (1/s²), k3 (1/s³)].
        """
        return vertical_damping_gains(self.damping_tau, lat, h) if self.mode == "damped" else np.zeros(3)


def vertical_channel(value, name: str = "vertical") -> VerticalChannel:
    """``value`` as a :class:`VerticalChannel`: one already, or a mode name (``"free"``, ...).

    Parameters
    ----------
    value : VerticalChannel or str
        The channel, or the name of a mode that needs no reference.
    name : str, optional
        The argument's name in the error message.

    Returns
    -------
    VerticalChannel
    """
    if isinstance(value, VerticalChannel):
        return value
    if isinstance(value, str):
        return VerticalChannel(value)
    raise TypeError(f"{name} must be a strapdown.VerticalChannel or a mode name ('free'), got {type(value).__name__}")


_UNUSED = np.zeros(1)   # the reference arrays of a mode that does not read them


def mechanize(t, dtheta, dv, initial: NavState, *, vertical: VerticalChannel | str = "free",
              polar_limit_deg: float = earth.POLAR_LIMIT_DEG) -> NavSolution:
    """Integrate IMU increments with the ENU strapdown algorithm (chen2019 eq. (3-2)).

    The update of the module docstring, one step per increment, compiled
    (``replication.nav._kernels.strapdown_kernel``); the inputs are checked here, once.

    Comparing the free vertical channel with another package: gravity here is the WGS-84
    normal gravity of :func:`replication.nav.earth.normal_gravity` (NIMA TR8350.2, Somigliana with
    the second-order height series), not a linear free-air term γ_0 - 3.086e-6 h.  The two
    differ by ~1e-7 m/s² at 150 m (more with another peer's constants or formula), and the
    free channel, unstable with rate sqrt(2g/R) ≈ 1.75e-3 s⁻¹, amplifies any such difference
    by about cosh(sqrt(2g/R) t) ≈ 280 in an hour: height differences against a peer's free
    channel of that origin are a choice of gravity model, not an error of either.

    Parameters
    ----------
    t : array_like, shape (N+1,)
        Sample times (s), strictly increasing.
    dtheta : array_like, shape (N, 3)
        Gyro increments Δθ (rad) in the body frame (Right-Front-Up); increment k covers
        t[k]..t[k+1].
    dv : array_like, shape (N, 3)
        Accelerometer increments Δv (m/s) in the body frame, over the same intervals.
    initial : NavState
        The navigation state at t[0].
    vertical : VerticalChannel or str, optional
        The vertical channel (:class:`VerticalChannel`), default free; e.g.
        ``VerticalChannel("hold", h_ref=traj.h)``.
    polar_limit_deg : float, optional
        Largest |latitude| (degrees) accepted for the initial state and reached by the solution.

    Returns
    -------
    NavSolution
        Position, velocity and attitude at the N+1 samples.

    Raises
    ------
    TypeError, ValueError
        For inputs of the wrong kind, shape or range, and when the solution reaches the polar
        singularity (with the time it happens).
    """
    dtheta, dv = validate_increments(dtheta, dv)
    n = len(dtheta)
    t, dt = _time_steps(t, n, "t")
    if not isinstance(initial, NavState):
        raise TypeError("initial must be a NavState (e.g. Trajectory.initial_state())")
    vc = vertical_channel(vertical)
    h_ref, vu_ref = vc.h_ref, vc.vu_ref
    initial.validate(name="initial", polar_limit_deg=polar_limit_deg)
    if vc.mode in ("hold", "damped"):
        if np.ndim(h_ref) and len(h_ref) != n + 1:
            raise ValueError(f"h_ref has {len(h_ref)} values; it needs one per sample ({n + 1})")
        href = _ref(h_ref, n + 1, "h_ref")
        earth.check_height(href, name="h_ref")
    else:
        href = _UNUSED
    if vu_ref is not None:
        if np.ndim(vu_ref) and len(vu_ref) != n + 1:
            raise ValueError(f"vu_ref has {len(vu_ref)} values; it needs one per sample ({n + 1})")
        vuref = _ref(vu_ref, n + 1, "vu_ref")
    else:
        vuref = np.zeros(n + 1) if vc.mode == "hold" else _UNUSED
    gains = vc.gains(initial.lat, initial.h)
    q0 = dcm_to_quat(initial.C_bn)
    out_st = np.empty((n + 1, 6))
    out_q = np.empty((n + 1, 4))
    bad = K.strapdown_kernel(dt, dtheta, dv, initial.vector(), q0, vc.code, href, vuref, gains,
                             out_st, out_q, np.radians(polar_limit_deg))
    if bad >= 0:
        raise ValueError(f"the solution reaches latitude {np.degrees(out_st[bad, 0]):.4f}° at t = {t[bad]:.3f} s, "
                         f"within the n-frame polar singularity (limit ±{polar_limit_deg}°); "
                         "use a grid-frame mechanization near the pole")
    return NavSolution(t, out_st[:, 0], out_st[:, 1], out_st[:, 2], out_st[:, 3:6], out_q)


def navigation_rates(lat, lon, h, v_enu, C_bn, w_ib_b, f_b, g_extra=None):
    """Continuous-time mechanization: (L̇, λ̇, ḣ, v̇^n, Ċ_b^n), chen2019 eq. (3-2).

    With the attitude equation Ċ_b^n = C_b^n (ω_ib^b ×) - (ω_in^n ×) C_b^n; the reference for the
    numerical Jacobian of the error model.  Arrays with leading batch dimensions are evaluated
    element by element.

    Parameters
    ----------
    lat, lon : float or array_like
        Latitude and longitude (rad).
    h : float or array_like
        Ellipsoidal height (m).
    v_enu : array_like, shape (..., 3)
        Velocity (m/s), East, North, Up.
    C_bn : array_like, shape (..., 3, 3)
        Attitude C_b^n.
    w_ib_b : array_like, shape (..., 3)
        Body angular rate ω_ib^b (rad/s).
    f_b : array_like, shape (..., 3)
        Specific force f^b (m/s²).
    g_extra : array_like, shape (..., 3), optional
        n-frame gravity disturbance (m/s²) added to the normal gravity.

    Returns
    -------
    tuple
        L̇ (rad/s), λ̇ (rad/s), ḣ (m/s), v̇^n (m/s², shape (..., 3)), Ċ_b^n (1/s, shape (..., 3, 3)).
    """
    lat = earth.check_latitude(lat, polar_limit_deg=earth.POLAR_LIMIT_DEG)
    earth.check_longitude(lon, name="lon")
    h = earth.check_height(h, name="h")
    v = earth.check_velocity(v_enu)
    C = rotation(C_bn, "C_bn")
    w_ib_b, f_b = vector3(w_ib_b, "w_ib_b"), vector3(f_b, "f_b")
    rm, rn = earth.radii(lat)
    w_ie = earth.earth_rate_enu(lat)
    w_en = earth.transport_rate_enu(lat, h, v)
    g = earth.gravity_enu(lat, h)
    if g_extra is not None:
        g = g + vector3(g_extra, "g_extra")
    f_n = C @ f_b
    vdot = f_n - np.cross(2 * w_ie + w_en, v) + g
    Cdot = C @ skew(w_ib_b) - skew(w_ie + w_en) @ C
    return (v[..., 1] / (rm + h), v[..., 0] / ((rn + h) * np.cos(lat)), v[..., 2], vdot, Cdot)
