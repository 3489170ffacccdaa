"""The error model of replication.nav.errors held against textbook results for the stationary INS.

* Observability (Bar-Itzhack & Berman 1988, "Control theoretic approach to inertial navigation
  systems", J. Guid. Control Dyn. 11(3); the single-channel form is in tests/test_observability.py):
  the 15-state stationary model observed through position and velocity has rank 12; its
  unobservable subspace is spanned by three directions, each a tilt or azimuth error held
  constant by the accelerometer bias and gyro drift that cancel its effect (∇_E = g φ_N,
  ∇_N = -g φ_E, ε_E = Ω sinL φ_N - Ω cosL φ_U, ε_N = -Ω sinL φ_E, ε_U = Ω cosL φ_E, in the
  package's signs: δf = ∇, δω = ε, Ĉ = (I - φ×) C).  Through velocity alone, the same
  equations leave three more directions unobserved: the longitude error (it enters no equation
  at rest), a height error held by ∇_U = (∂γ/∂h) δh, and a latitude error whose Earth-rate error
  is held by ε_N = -Ω sinL δL, ε_U = Ω cosL δL and whose gravity change by ∇_U = (∂γ/∂L) δL:
  rank 9.
* Schuler and Foucault (Britting 1971 §10; Titterton & Weston 2004 §12.3): the horizontal error
  dynamics at rest have the characteristic polynomial (s² + Ω²)[(s² + ω_s²)² + 4 s² Ω² sin²L],
  roots ±iΩ and ±i(√(ω_s² + Ω² sin²L) ± Ω sinL), ω_s = √(g/R): the Schuler pair split by the
  Foucault frequency Ω sinL; the free vertical channel has ±√(2g/R).
"""

from __future__ import annotations

import numpy as np
import pytest

from replication.nav import earth
from replication.nav import errors as er
from replication.nav.errors import NavPoint
from replication.papers.chen2019 import observability as O

W = earth.OMEGA_IE


def _stationary(lat_deg):
    """The 15-state F at rest, level, heading north (body = ENU), and (g, mean radius)."""
    lat = np.radians(lat_deg)
    g = float(earth.normal_gravity(lat, 0.0))
    point = NavPoint(lat, 0.0, 0.0, np.zeros(3), np.eye(3), np.array([0.0, 0.0, g]), earth.earth_rate_enu(lat))
    rm, rn = earth.radii(lat)
    return er.model_15().F(point), g, float(np.sqrt(rm * rn)), lat


def _null_directions(lat, g):
    """The three textbook unobservable directions in the package's state order and signs."""
    s, c = W * np.sin(lat), W * np.cos(lat)
    n = np.zeros((15, 3))
    # φ_E = 1: ∇_N = -g, ε_N = -Ω sinL, ε_U = Ω cosL
    n[6, 0], n[10, 0], n[13, 0], n[14, 0] = 1.0, -g, -s, c
    # φ_N = 1: ∇_E = g, ε_E = Ω sinL
    n[7, 1], n[9, 1], n[12, 1] = 1.0, g, s
    # φ_U = 1: ε_E = -Ω cosL
    n[8, 2], n[12, 2] = 1.0, -c
    return n


def _dgamma_dh(lat):
    """∂γ/∂h at h = 0 of the TR8350.2 series: -2γ_0/a (1 + f + m - 2f sin²L)."""
    return -2.0 * float(earth.normal_gravity(lat, 0.0)) / earth.A * (1 + earth.F + earth.M_RATIO - 2 * earth.F * np.sin(lat) ** 2)


def _dgamma_dlat(lat):
    """∂γ_0/∂L of Somigliana γ_0 = γ_e (1 + k sin²L)/√(1 - e² sin²L)."""
    s2, k, e2 = np.sin(lat) ** 2, earth.K_SOMIGLIANA, earth.E2
    w = 1.0 - e2 * s2
    return earth.GAMMA_E * np.sin(2 * lat) * (k / np.sqrt(w) + (1 + k * s2) * e2 / (2 * w**1.5))


SCALE = np.r_[1e-6, 1e-6, 1.0, 1.0, 1.0, 1.0, 1e-3, 1e-3, 1e-3, 1e-2, 1e-2, 1e-2, 1e-6, 1e-6, 1e-6]
"""States in units of typical errors (rad, rad, m, m/s, rad, m/s², rad/s) for a balanced SVD."""


@pytest.mark.parametrize("lat_deg", [20.0, 45.0, 70.0])
@pytest.mark.parametrize("measured, rank", [("position and velocity", 12), ("velocity", 9)])
def test_stationary_ins_observability_rank_and_null_space(lat_deg, measured, rank):
    # source: Bar-Itzhack & Berman 1988 (stationary INS, module docstring); tolerance: the null
    # directions annihilate Q to round-off (1e-12 of σ_max; the rank gap is 1e-13 vs 1e-2 here)
    F, g, R, lat = _stationary(lat_deg)
    rm, rn = earth.radii(lat)
    H = np.zeros((6, 15))
    H[0, 0], H[1, 1], H[2, 2] = rm, rn * np.cos(lat), 1.0            # position in metres
    H[3:6, 3:6] = np.eye(3)
    if measured == "velocity":
        H = H[3:]
    T = np.sqrt(R / g)                                               # time in Schuler units: Q(FT) has Q(F)'s null space
    Q = O.observability_matrix(F * T, H)
    deg = O.observability_degrees(Q, normalize="scale", state_scale=SCALE)
    assert deg.rank == rank
    null = _null_directions(lat, g)
    if measured == "velocity":
        extra = np.zeros((15, 3))
        extra[1, 0] = 1.0                                            # δλ
        extra[2, 1], extra[11, 1] = 1.0, _dgamma_dh(lat)             # δh, ∇_U
        extra[0, 2], extra[13, 2], extra[14, 2] = 1.0, -W * np.sin(lat), W * np.cos(lat)  # δL, ε_N, ε_U
        extra[11, 2] = _dgamma_dlat(lat)                             # ∇_U
        null = np.column_stack([null, extra])
    assert null.shape[1] == 15 - rank
    y = null / SCALE[:, None]                                        # in the scaled states of the SVD
    sigma_max = deg.singular_values[0]
    assert np.max(np.linalg.norm((Q * SCALE) @ y, axis=0) / np.linalg.norm(y, axis=0)) < 1e-12 * sigma_max
    assert np.linalg.matrix_rank(null) == null.shape[1]


@pytest.mark.parametrize("lat_deg", [20.0, 45.0, 70.0])
def test_stationary_error_dynamics_have_the_schuler_foucault_and_earth_rate_modes(lat_deg):
    # source: Britting 1971 / Titterton & Weston 2004 §12.3 (module docstring); tolerance 2e-3 relative
    # on each frequency: the textbook drops terms of relative order Ω²/ω_s² = 3.4e-3 in ω² and
    # models a sphere (the mean radius √(R_M R_N) absorbs the first order of e² cos²L); 3e-3 on the
    # vertical root, whose -∂γ/∂h exceeds 2g/R by (f + m - 2f sin²L) ≈ 0.3 %
    F, g, R, lat = _stationary(lat_deg)
    ev = np.linalg.eigvals(F[:9, :9])
    real = np.sort(ev[np.abs(ev.imag) < 1e-12].real)
    osc = np.sort(np.abs(ev.imag[ev.imag > 1e-12]))
    assert real.size == 3 and osc.size == 3                         # 0, ±ω_v and three oscillations
    assert np.max(np.abs(ev[np.abs(ev.imag) > 1e-12].real)) < 1e-15   # neutrally stable (no damping)
    ws, sf = np.sqrt(g / R), W * np.sin(lat)
    expected = np.sort([W, np.hypot(ws, sf) - sf, np.hypot(ws, sf) + sf])
    np.testing.assert_allclose(osc, expected, rtol=2e-3)
    assert osc[2] - osc[1] == pytest.approx(2 * sf, rel=5e-3)        # the Foucault splitting, same order
    np.testing.assert_allclose(real, [-np.sqrt(2 * g / R), 0.0, np.sqrt(2 * g / R)], rtol=3e-3, atol=1e-12)
