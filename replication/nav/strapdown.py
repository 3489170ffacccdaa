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

__all__ = ["NavState", "NavSolution", "mechanize", "navigation_rates", "vertical_damping_gains",
           "validate_time", "validate_increments", "VERTICAL_MODES"]

VERTICAL_MODES = {"free": 0, "hold": 1, "damped": 2}


@dataclass
class NavState:
    """Navigation state: geodetic position (rad, rad, m), ENU velocity (m/s), attitude C_b^n."""

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
        """Check every field (also after a field was changed): latitude within ±90° and outside the polar
        singularity, finite longitude, height within :data:`replication.nav.earth.HEIGHT_RANGE`, finite
        velocity below :data:`replication.nav.earth.SPEED_LIMIT`, C_bn a rotation matrix
        (``_validate.ORTHONORMAL_TOL``).  Raises ``TypeError``/``ValueError`` naming the
        field; the compiled mechanization checks nothing."""
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
        return cls(lat, lon, h, v_enu, euler_to_dcm(heading, pitch, roll))

    def vector(self):
        return np.array([self.lat, self.lon, self.h, *self.v_enu])


@dataclass
class NavSolution:
    """Strapdown output at the N+1 sample instants."""

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_enu: np.ndarray
    q_bn: np.ndarray

    @property
    def C_bn(self):
        return quat_to_dcm(self.q_bn)

    @property
    def hpr(self):
        return np.stack(dcm_to_euler(self.C_bn), -1)

    @property
    def position(self):
        return np.stack([self.lat, self.lon, self.h], -1)

    def errors_against(self, truth):
        """Errors against a :class:`~replication.nav.trajectory.Trajectory` with the same samples.

        Returns a dict: ``east``, ``north``, ``up`` (m), ``v`` (m/s, ENU), ``phi`` (rad, n-frame
        misalignment with Ĉ = exp(-φ×) C)."""

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


def validate_time(t, n_increments: int | None = None, name: str = "t"):
    """Check a time vector: 1-D, finite, strictly increasing, matching the increments."""
    t = numeric(t, name)
    if t.ndim != 1 or len(t) < 2:
        raise ValueError(f"{name} must be a 1-D array of at least two sample times")
    if not np.all(np.isfinite(t)):
        raise ValueError(f"{name} contains NaN or infinite values")
    d = np.diff(t)
    if np.any(d <= 0):
        k = int(np.argmax(d <= 0))
        raise ValueError(f"{name} must be strictly increasing: {name}[{k + 1}] = {t[k + 1]!r} follows "
                         f"{name}[{k}] = {t[k]!r}; sort the record or drop duplicated samples")
    if n_increments is not None and len(t) != n_increments + 1:
        raise ValueError(f"{name} has {len(t)} samples but there are {n_increments} increments: "
                         f"increments k = 1..N lie between samples, so len({name}) must be N + 1 = {n_increments + 1}")
    return t


def validate_increments(dtheta, dv):
    dtheta = np.ascontiguousarray(numeric(dtheta, "dtheta"))
    dv = np.ascontiguousarray(numeric(dv, "dv"))
    if dtheta.ndim != 2 or dtheta.shape[1] != 3:
        raise ValueError(f"dtheta must have shape (N, 3), got {dtheta.shape}")
    if dv.shape != dtheta.shape:
        raise ValueError(f"dtheta and dv must have the same shape (one gyro and one accelerometer increment "
                         f"per interval), got {dtheta.shape} and {dv.shape}")
    if not (np.all(np.isfinite(dtheta)) and np.all(np.isfinite(dv))):
        raise ValueError("increments contain NaN or infinite values")
    return dtheta, dv


def vertical_damping_gains(tau: float = 100.0, lat: float = 0.0, h: float = 0.0):
    """Third-order vertical-loop gains placing all three poles at -1/τ.

    With δḣ = δv_U - k1 δh, δv̇_U = (2γ/R) δh - k2 δh - k3 ∫δh, the characteristic polynomial is
    s³ + k1 s² + (k2 - 2γ/R) s + k3 = (s + 1/τ)³.
    """
    tau = positive(tau, "tau", "the damping time constant {name} must be positive (seconds), got {value!r}")
    g = float(earth.normal_gravity(lat, h))
    rm, rn = earth.radii(lat)
    ws2 = 2 * g / float(np.sqrt(rm * rn) + h)
    return np.array([3 / tau, 3 / tau**2 + ws2, 1 / tau**3])


def _ref(arr, n, name):
    a = np.ascontiguousarray(np.broadcast_to(numeric(arr, name), (n,)), dtype=float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return a


def mechanize(t, dtheta, dv, initial: NavState, *, vertical: str = "free", h_ref=None, vu_ref=None,
              damping_tau: float = 100.0, polar_limit_deg: float = earth.POLAR_LIMIT_DEG) -> NavSolution:
    """Integrate IMU increments with the ENU strapdown algorithm (chen2019 eq. (3-2)).

    ``t`` holds the N+1 sample times (s, strictly increasing); ``dtheta`` and ``dv`` the (N, 3)
    gyro and accelerometer increments Δθ (rad), Δv (m/s) in the body frame (Right-Front-Up),
    increment k covering t[k]..t[k+1]; ``initial`` the navigation state at t[0].
    ``vertical`` is "free", "hold" (needs ``h_ref`` and optionally ``vu_ref``, N+1 values each:
    the papers' height channel held to the true height) or "damped" (third-order loop on
    ``h_ref``, e.g. a barometric height, with poles at -1/``damping_tau``).

    Comparing the free vertical channel with another package: gravity here is the WGS-84
    normal gravity of :func:`replication.nav.earth.normal_gravity` (NIMA TR8350.2, Somigliana with
    the second-order height series), not a linear free-air term γ_0 - 3.086e-6 h.  The two
    differ by ~1e-7 m/s² at 150 m (more with another peer's constants or formula), and the
    free channel, unstable with rate sqrt(2g/R) ≈ 1.75e-3 s⁻¹, amplifies any such difference
    by about cosh(sqrt(2g/R) t) ≈ 280 in an hour: height differences against a peer's free
    channel of that origin are a choice of gravity model, not an error of either.
    """
    dtheta, dv = validate_increments(dtheta, dv)
    n = len(dtheta)
    t = validate_time(t, n)
    if not isinstance(initial, NavState):
        raise TypeError("initial must be a NavState (e.g. Trajectory.initial_state())")
    choice(vertical, sorted(VERTICAL_MODES), "vertical")
    initial.validate(name="initial", polar_limit_deg=polar_limit_deg)
    if vertical in ("hold", "damped"):
        if h_ref is None:
            raise ValueError(f"vertical={vertical!r} needs h_ref (reference heights at the N+1 samples)")
        if np.ndim(h_ref) and len(h_ref) != n + 1:
            raise ValueError(f"h_ref has {len(h_ref)} values; it needs one per sample ({n + 1})")
        href = _ref(h_ref, n + 1, "h_ref")
        earth.check_height(href, name="h_ref")
    else:
        href = np.zeros(n + 1)
    if vu_ref is not None and np.ndim(vu_ref) and len(vu_ref) != n + 1:
        raise ValueError(f"vu_ref has {len(vu_ref)} values; it needs one per sample ({n + 1})")
    vuref = _ref(0.0 if vu_ref is None else vu_ref, n + 1, "vu_ref")
    gains = vertical_damping_gains(damping_tau, initial.lat, initial.h) if vertical == "damped" else np.zeros(3)
    st0 = initial.vector()
    q0 = dcm_to_quat(initial.C_bn)
    out_st = np.empty((n + 1, 6))
    out_q = np.empty((n + 1, 4))
    K.strapdown_kernel(np.diff(t), dtheta, dv, st0, q0, VERTICAL_MODES[vertical], href, vuref, gains, out_st, out_q)
    lat = out_st[:, 0]
    if np.any(np.abs(lat) >= np.radians(polar_limit_deg)) or not np.all(np.isfinite(lat)):
        bad = int(np.argmax(~np.isfinite(lat) | (np.abs(lat) >= np.radians(polar_limit_deg))))
        raise ValueError(f"the solution reaches latitude {np.degrees(lat[bad]):.4f}° at t = {t[bad]:.3f} s, "
                         f"within the n-frame polar singularity (limit ±{polar_limit_deg}°); "
                         "use a grid-frame mechanization near the pole")
    return NavSolution(t, lat, out_st[:, 1], out_st[:, 2], out_st[:, 3:6], out_q)


def navigation_rates(lat, lon, h, v_enu, C_bn, w_ib_b, f_b, g_extra=None):
    """Continuous-time mechanization: (L̇, λ̇, ḣ, v̇^n, Ċ_b^n) — chen2019 eq. (3-2) and the
    attitude equation Ċ_b^n = C_b^n (ω_ib^b ×) - (ω_in^n ×) C_b^n.

    Used as the reference for the numerical Jacobian of the error model.  ``g_extra`` adds an
    n-frame gravity disturbance to the normal gravity.
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
