"""The two-point comprehensive calibration of fang2020 eqs. (25)-(27).

:func:`two_point_drift` estimates the gyro drift from the ψ of two position fixes through the
solution T, U of eq. (25) (:mod:`replication.papers.fang2020.error_equations`), with the matrix
B the paper leaves undefined (:func:`b_matrix`, ``DRIFT_CONVENTIONS``); :func:`drift_from_psi`
is the inversion for given ψ, and :func:`fix_drift_resolution` the drift a fix's position
resolution leaves undetermined.

Sign conventions.  Small-angle frame errors carry the true grid frame G to another frame:
θ: G → c (computer), φ: G → p (platform), ψ: c → p, with v^p = (I - [φ×]) v^G, so φ = θ + ψ.
Position errors are computed minus true; heading errors are the indicated grid heading (clockwise
from grid north) minus the true one, which equals φ_z.  Gyro drift ε_b is the gyro output minus
the true rate (strapdown convention); fang2020's ψ equation (18)-(24) is written for the
*platform drift rate*, which for a strapdown navigator is -C_b^G ε_b — see
:func:`~replication.papers.fang2020.two_point.b_matrix`.
"""

from __future__ import annotations

import numpy as np

from replication.nav import earth
from replication.nav._validate import choice, positive, vector3
from replication.papers.fang2020.error_equations import OMEGA, input_u, m_matrix, transition_t
from replication.papers.fang2020.frames import _angle, gaussian_radius, grid_azimuth, oepq_frame, oepq_to_grid

DRIFT_CONVENTIONS = ("gyro-error", "platform-drift")
"""Meaning of ε: gyro output minus true rate (strapdown), or platform drift rate (fang2020 eq. (18))."""


def b_matrix(lat, sigma, convention="gyro-error"):
    """The matrix B of fang2020 eq. (25), which the paper does not define.

    Derivation.  The ψ equation (24) is linear with constant coefficients in OEPQ components:
    ψ̇ = A ψ + ε_OEPQ.  Its solution over [t_n, t_{n+1}] is ψ(t_{n+1}) = T ψ(t_n) + (U/Ω) ε_OEPQ,
    with T = exp(Aτ) and U/Ω = ∫₀^τ exp(As) ds exactly the printed T and U.  Hence
    ε_OEPQ = Ω U⁻¹[ψ(t_{n+1}) - T ψ(t_n)].  The printed left factor C_G^b takes *grid* components
    to body components, so B must take OEPQ components to grid components: B = C_OEPQ^G of
    eq. (16) — times the sign that relates the paper's ε to the gyro error.  In (18) ε is the
    platform drift rate (ω_ip = ω_ic + ψ×ω_ic + ε); a strapdown navigator integrating gyro outputs
    ω + ε_b rotates its platform at ω_ic - C_b^p ε_b, so ε = -C_b^G ε_b and

        ``convention="gyro-error"``: B = -C_OEPQ^G   (ε_b = gyro output minus true rate),
        ``convention="platform-drift"``: B = +C_OEPQ^G (ε_b = platform drift rate, gimballed).

    Parameters
    ----------
    lat : float or array_like
        Latitude L [rad], |L| ≤ 90°.
    sigma : float or array_like
        Grid azimuth σ [rad] (:func:`~replication.papers.fang2020.frames.grid_azimuth`).
    convention : {"gyro-error", "platform-drift"}, default "gyro-error"
        Meaning of ε (:data:`DRIFT_CONVENTIONS`, :func:`b_matrix`).

    Returns
    -------
    b : numpy.ndarray, shape (..., 3, 3)
        B = ∓C_OEPQ^G (dimensionless).

    Raises
    ------
    ValueError
        If ``convention`` is unknown, or for ``lat`` and ``sigma`` as :func:`~replication.papers.fang2020.frames.oepq_to_grid`.
    """
    choice(convention, DRIFT_CONVENTIONS, "convention")
    c = oepq_to_grid(lat, sigma)
    return -c if convention == "gyro-error" else c


def fix_drift_resolution(heading_error: float, fix_times) -> float:
    """The drift the two-point scheme cannot tell from a heading-reference error at one fix.

    The scheme (fang2020 eqs. (25)-(27)) reads the drift from the change of the platform drift
    angle between the two fixes; an error e of the heading reference at one fix is read as a drift
    e / (t_2 - t_1) about the vertical.  This is the loosest bound the printed external information
    sets (fang2020 §3: 6″ over the 1.5 h between the fixes); the 5-m position errors bound the
    level components far tighter (5 m / R ≈ 0.16″).

    Parameters
    ----------
    heading_error : float
        Error of the heading reference at a fix [rad].
    fix_times : tuple of float
        The two fix times (t_1, t_2) [s], t_2 > t_1.

    Returns
    -------
    float
        The drift [rad/s], non-negative.

    Raises
    ------
    ValueError
        If the fix times are not two finite numbers with t_2 > t_1, or ``heading_error`` is not finite.
    """
    t = np.asarray(fix_times, dtype=float)
    if t.shape != (2,) or not np.all(np.isfinite(t)) or not t[1] > t[0]:
        raise ValueError(f"fix_times must be two finite times with t_2 > t_1, not {fix_times!r}")
    if not np.isfinite(heading_error):
        raise ValueError(f"heading_error must be finite, not {heading_error!r}")
    return float(abs(heading_error) / (t[1] - t[0]))


def two_point_drift(p2, r2, c_b_g, tau, *, p1=None, r1=None, mean_c_b_e=None,
                    convention="gyro-error", radius=None):
    """Gyro constant drift in the body frame from two fixes, fang2020 eqs. (25)-(27).

    ε_b = C_G^b B Ω U⁻¹ [M⁻¹(t_{n+1}) P(t_{n+1}) - T M⁻¹(t_n) P(t_n)]        (26)
    with P(t_n⁺) = 0 after the first reset (``p1=None``) giving eq. (27).  B from :func:`b_matrix`.
    ψ(t_n) is rotated from OEPQ at the first fix into OEPQ at the second (about P).

    With ``mean_c_b_e``: the ψ equation integrates ε_OEPQ(t) = C_b^OEPQ(t) ε_b, so for a rocking
    ship the attitude that inverts it is the mean ⟨C_b^OEPQ⟩ = C_e^OEPQ(λ_{n+1}) ⟨C_b^e⟩, not the
    attitude at one instant; then ε_b = s ⟨C_b^OEPQ⟩⁻¹ Ω U⁻¹[...] (s = -1 for gyro errors), which
    equals eq. (27) for a ship holding a constant attitude.  Works on batches (leading axes).

    Parameters
    ----------
    p2 : array_like, shape (..., 3)
        P(t_{n+1}) = (δx [m], δy [m], φ_z [rad]) observed at the second fix, computed minus
        reference.
    r2 : array_like, shape (..., 3)
        ECEF position of the second fix [m], mapped to the osculating sphere where M of eq. (17)
        is evaluated.
    c_b_g : array_like, shape (..., 3, 3)
        C_b^G at t_{n+1} (its transpose is the printed C_G^b); not used when ``mean_c_b_e`` is
        given.
    tau : float
        t_{n+1} - t_n [s], positive.
    p1 : array_like, shape (..., 3), optional
        P(t_n) at the first fix (eq. (26)); None: P(t_n⁺) = 0 (eq. (27)).  Give it with ``r1``.
    r1 : array_like, shape (..., 3), optional
        ECEF position of the first fix [m]; given together with ``p1``.
    mean_c_b_e : array_like, shape (..., 3, 3), optional
        The interval mean ⟨C_b^e⟩ over [t_n, t_{n+1}].
    convention : {"gyro-error", "platform-drift"}, default "gyro-error"
        Meaning of ε (:data:`DRIFT_CONVENTIONS`, :func:`b_matrix`).
    radius : float, optional
        Sphere radius [m] on which M is evaluated; default the Gaussian radius at each fix
        (:func:`~replication.papers.fang2020.frames.gaussian_radius`).

    Returns
    -------
    eps_b : numpy.ndarray, shape (..., 3)
        Gyro constant drift ε_b [rad/s] in body axes (x right, y forward, z up).

    Raises
    ------
    ValueError
        If only one of ``p1``, ``r1`` is given, ``convention`` is unknown, ``tau`` is not positive
        or an array has the wrong shape.
    """
    p2 = vector3(p2, "p2")
    r2 = vector3(r2, "r2 (ECEF, m)")
    tau = positive(tau, "tau (s)")
    choice(convention, DRIFT_CONVENTIONS, "convention")
    if (p1 is None) != (r1 is None):
        raise ValueError("give both p1 and r1 (eq. (26)) or neither (eq. (27), P(t_n+) = 0)")
    lat2, lon2, _ = earth.ecef_to_geodetic(r2)
    rad2 = gaussian_radius(lat2) if radius is None else np.broadcast_to(positive(radius, "radius"), lat2.shape)
    psi2 = _psi_at(p2, lat2, lon2, rad2)
    a = OMEGA * tau
    t_mat = transition_t(a)
    rhs = psi2
    if p1 is not None:
        p1 = vector3(p1, "p1")
        lat1, lon1, _ = earth.ecef_to_geodetic(vector3(r1, "r1 (ECEF, m)"))
        rad1 = gaussian_radius(lat1) if radius is None else np.broadcast_to(float(radius), lat1.shape)
        # ψ(t_n) is expressed in OEPQ at the first fix; rotate it into OEPQ of the second (about P)
        psi1 = _psi_at(p1, lat1, lon1, rad1)
        rot = oepq_frame(lon2) @ np.swapaxes(oepq_frame(lon1), -1, -2)
        rhs = rhs - np.einsum("ij,...jk,...k->...i", t_mat, rot, psi1)
    return drift_from_psi(rhs, lat2, lon2, c_b_g, tau, mean_c_b_e=mean_c_b_e, convention=convention)


def drift_from_psi(dpsi, lat, lon, c_b_g, tau, *, mean_c_b_e=None, convention="gyro-error"):
    """ε_b = C_G^b B Ω U⁻¹ Δψ, fang2020 eq. (25); see :func:`two_point_drift`.

    Δψ = ψ(t_{n+1}) - T ψ(t_n) in OEPQ components at the second fix.

    Parameters
    ----------
    dpsi : array_like, shape (..., 3)
        Δψ [rad] in OEPQ components at (``lat``, ``lon``).
    lat : float or array_like
        Latitude of the second fix [rad].
    lon : float or array_like
        Longitude of the second fix [rad].
    c_b_g : array_like, shape (..., 3, 3)
        C_b^G at the second fix; not used when ``mean_c_b_e`` is given.
    tau : float
        t_{n+1} - t_n [s], positive.
    mean_c_b_e : array_like, shape (..., 3, 3), optional
        Interval mean ⟨C_b^e⟩ that replaces the attitude at the fix (:func:`two_point_drift`).
    convention : {"gyro-error", "platform-drift"}, default "gyro-error"
        Meaning of ε (:data:`DRIFT_CONVENTIONS`, :func:`b_matrix`).

    Returns
    -------
    eps_b : numpy.ndarray, shape (..., 3)
        Gyro constant drift ε_b [rad/s] in body axes.

    Raises
    ------
    ValueError
        If ``convention`` is unknown, ``tau`` is not positive or an array has the wrong shape.
    """
    rhs = vector3(dpsi, "dpsi")
    tau = positive(tau, "tau (s)")
    choice(convention, DRIFT_CONVENTIONS, "convention")
    lat2 = earth.check_latitude(lat)
    lon2 = _angle(lon, "lon")
    u_mat = input_u(OMEGA * tau)
    eps_oepq = OMEGA * np.linalg.solve(u_mat, rhs[..., None])[..., 0]
    sign = -1.0 if convention == "gyro-error" else 1.0
    if mean_c_b_e is None:
        c_b_g = np.asarray(c_b_g, dtype=float)
        if c_b_g.shape[-2:] != (3, 3):
            raise ValueError(f"c_b_g must be (..., 3, 3), got {c_b_g.shape}")
        sigma = grid_azimuth(lat2, lon2)
        bm = b_matrix(lat2, sigma, convention)
        return np.einsum("...ji,...jk,...k->...i", c_b_g, bm, eps_oepq)
    mc = np.asarray(mean_c_b_e, dtype=float)
    if mc.shape[-2:] != (3, 3):
        raise ValueError(f"mean_c_b_e must be (..., 3, 3), got {mc.shape}")
    c_b_oepq = oepq_frame(lon2) @ mc
    return sign * np.linalg.solve(c_b_oepq, eps_oepq[..., None])[..., 0]


def _psi_at(p, lat, lon, rad):
    pts = np.stack([rad * np.cos(lat) * np.cos(lon), rad * np.cos(lat) * np.sin(lon), rad * np.sin(lat)], -1)
    m = m_matrix(pts, None)
    return np.linalg.solve(m, p[..., None])[..., 0]
