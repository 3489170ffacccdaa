"""The measurements of the closed-loop filter as values (replication.nav.measurements).

Each aid supplies a compiled ``rows`` and ``residual`` kernel of one signature; the filter
(:func:`replication.nav.filter.run_filter`) calls them in turn and never names one.  These tests
hold every aid to its number of rows and variances, its rows to the derivative of its residual,
the zero-velocity and barometric aids to a dense textbook Kalman update (numpy), the chen2019
measurement matrix to the GNSS aids, and show an aid added by one module written elsewhere."""

import importlib.util
import sys
import textwrap

import numpy as np
import pytest

from replication.nav import _kernels as K
from replication.nav import closedloop as cl
from replication.nav import errors as er
from replication.nav import filter as nf
from replication.nav import trajectory as tr
from replication.nav.measurements import CTX_FACC, CTX_VACC, Measurement, ctx_size, ctx_window
from replication.nav.measurements.airdata import AirHeight, Airspeed
from replication.nav.measurements.baro import BaroHeight, pressure_height
from replication.nav.measurements.gnss import GnssPosition, GnssVelocity
from replication.nav.measurements.specific_force import SpecificForce
from replication.nav.measurements.zupt import ZeroVelocity
from replication.nav.rotations import dcm_to_quat, rotvec_to_dcm
from replication.nav.units import DEG
from replication.papers.chen2019 import models as M


def _model():
    """A 15-state model with a lever arm and three aid error states (air height, airspeed, barometer)."""
    air = er.StateBlock("air", ("h", "V", "baro"), "none", dynamics=-np.eye(3) / 300.0, noise_psd=np.eye(3) * 1e-3,
                        sd=np.array([1.0, 0.5, 2.0]))
    return er.model_15(lat=0.8, h=3000.0).extend(er.lever_arm(0.1), air)


def _context(m, st, lever, w, p_hat):
    """The epoch context of the measurement kernels (lead's window sums and run's sums set)."""
    n = m.n
    ctx = np.zeros(ctx_size(n))
    ctx[0:6], ctx[6:9], ctx[9:12], ctx[18] = st, lever, w, n
    ctx[CTX_FACC:CTX_FACC + 3] = (0.1, 0.2, 9.8)
    ctx[CTX_VACC:CTX_VACC + 3] = (0.1, -0.2, 0.3)
    ctx[19:19 + n - 9] = p_hat
    cw = ctx_window(n)
    ctx[cw:cw + 6 * n] = np.linspace(-1, 1, 6 * n)
    return ctx


def _setting():
    """Every generic aid with values where the INS (state ``st``) puts them."""
    m = _model()
    col = m.slices["air"].start
    st = np.array([0.8, 2.0, 3000.0, 80.0, -40.0, 2.0])
    c = rotvec_to_dcm(np.array([0.05, -0.03, 1.1]))
    lever = np.array([0.4, -1.2, 2.5])
    w = np.array([0.01, -0.02, 0.15])
    rm, rn = K.radii_s(st[0])
    la = c @ lever
    gpos = np.array([st[0] + la[1] / (rm + st[2]), st[1] + la[0] / ((rn + st[2]) * np.cos(st[0])), st[2] + la[2]])
    gvel = st[3:6] + c @ np.cross(w, lever)
    p = 101325.0 * (1 - 0.0065 * st[2] / 288.15) ** (9.80665 / (287.05287 * 0.0065))
    aids = {"gnss_position": (GnssPosition([0.01, 0.02, 0.03]), gpos),
            "gnss_velocity": (GnssVelocity([1e-4, 2e-4, 3e-4]), gvel),
            "specific_force": (SpecificForce(np.ones((3, m.n - 9))), np.array([1.0, 0.1, -0.2, 0.3, 1e-4, 2e-4, 3e-4])),
            "air_height": (AirHeight(1.0, col), np.array([st[2]])),
            "airspeed": (Airspeed(0.25, col + 1), np.array([np.linalg.norm(st[3:6])])),
            "zero_velocity": (ZeroVelocity([1e-4, 1e-4, 4e-4]), np.array([1.0])),
            "baro_height": (BaroHeight(4.0, col + 2), np.array([p]))}
    return m, aids, (c, lever, w, st)


def _rows(m, aid, data, nav, p_hat=None):
    c, lever, w, st = nav
    H = np.zeros((4, m.n))
    Rd = np.zeros(4)
    _, _, tg, kd, bs, bz = m.kernel_encoding()
    ctx = _context(m, st, lever, w, np.zeros(m.n - 9) if p_hat is None else p_hat)
    k = type(aid).rows_kernel(aid.parameters(m), data, ctx, np.ascontiguousarray(c), np.vstack([tg, kd, bs, bz]),
                              H, Rd, 0)
    return k, H[:k], Rd[:k]


def _residuals(m, aid, data, nav, p_hat=None):
    c, lever, w, st = nav
    z = np.zeros(4)
    ctx = _context(m, st, lever, w, np.zeros(m.n - 9) if p_hat is None else p_hat)
    k = type(aid).residual_kernel(aid.parameters(m), data, ctx, np.ascontiguousarray(c), z, 0)
    return k, z[:k]


def test_every_aid_writes_its_rows_and_residuals():
    """Each aid writes ``size`` rows with its variances, and as many residuals; where the INS and
    the aid agree the residual is zero (to rounding of the radii: 1e-6 m)."""
    m, aids, nav = _setting()
    for name, (aid, data) in aids.items():
        k, H, Rd = _rows(m, aid, data, nav)
        assert k == aid.size and np.all(np.any(H != 0, axis=1)), name
        kz, z = _residuals(m, aid, data, nav)
        assert kz == k, name
        if name == "specific_force":
            assert np.array_equal(Rd, data[4:7])
        else:
            assert np.array_equal(Rd, aid.parameters(m)[:k] if aid.size == 3 else aid.parameters(m)[:1]), name
        if name not in ("specific_force", "zero_velocity"):
            assert np.max(np.abs(z)) < 1e-6, (name, z)
    # no rows where no window ends, or where the vehicle moves
    for name, off in (("specific_force", np.zeros(7)), ("zero_velocity", np.zeros(1))):
        assert _rows(m, aids[name][0], off, nav)[0] == 0 and _residuals(m, aids[name][0], off, nav)[0] == 0


@pytest.mark.parametrize("name", ["gnss_position", "gnss_velocity", "air_height", "airspeed", "zero_velocity",
                                  "baro_height"])
def test_rows_are_the_derivative_of_the_residuals(name):
    """H's navigation columns are the derivative of the aid's residual with respect to the INS
    state [L, λ, h, v] (an INS error δx moves the residual by H δx), its error-state column (−1:
    INS minus aid) the negative of the derivative with respect to the accumulated estimate.
    Central differences, steps 1e-3 of each state's scale: the residuals are at most quadratic in
    the step, so 1e-6 column-relative leaves room for the curvature of the radii and rounding."""
    m, aids, nav = _setting()
    aid, data = aids[name]
    k, H, _ = _rows(m, aid, data, nav)
    c, lever, w, st = nav
    scale = np.array([1e-6, 1e-6, 1.0, 0.1, 0.1, 0.1])
    J = np.empty((k, 6))
    for i in range(6):
        d = np.zeros(6)
        d[i] = 1e-3 * scale[i]
        J[:, i] = (_residuals(m, aid, data, (c, lever, w, st + d))[1]
                   - _residuals(m, aid, data, (c, lever, w, st - d))[1]) / (2 * d[i])
    colmax = np.maximum(np.abs(J).max(0), np.abs(H[:, :6]).max(0)) + 1e-300
    assert np.max(np.abs(H[:, :6] - J) / colmax) < 1e-6
    cols = [j for j in range(9, m.n) if np.any(H[:, j] != 0) and j not in range(*m.slices["lever_arm"].indices(m.n))]
    for col in cols:
        p = np.zeros(m.n - 9)
        p[col - 9] = 0.7
        dz = (_residuals(m, aid, data, nav, p)[1] - _residuals(m, aid, data, nav)[1]) / 0.7
        assert np.allclose(dz, -H[:, col], rtol=0, atol=1e-12) and np.all(H[:, col] == -1.0)


def test_chen2019_measurement_matrix_is_the_gnss_aids():
    """chen2019 eq. (2-13) as ``models.measurement_matrix`` writes it and the filter's GNSS aids are
    one measurement: H_chen2019(l) = P H_aids(−l) S, exactly to rounding (1e-12 of each column),
    where P orders the rows as chen2019's Z (north, east, up, then velocity E, N, U); the lever arm
    has the opposite sense (chen2019 carries the fix from the antenna to the SINS centre, the aids
    from the IMU to the antenna), so the aids are evaluated with −l; S = −1 on the lever-arm states."""
    traj = tr.generate([tr.Straight(5.0), tr.Turn(10.0, np.pi / 2)], 47 * DEG, 115 * DEG, 3000.0,
                       heading=30 * DEG, speed=100.0, dt=0.01)
    m = M.model_45()
    p = er.NavPoint.from_trajectory(traj, 1200)
    lever = np.array([0.4, -1.2, 2.5])
    H_chen = M.measurement_matrix(m, p, lever)
    C = np.asarray(p.C_bn, float)
    w = np.asarray(M._w_eb_b(p), float)
    st = np.array([p.lat, 0.0, p.h, 0.0, 0.0, 0.0])
    nav = (C, -lever, w, st)
    H = np.vstack([_rows(m, GnssPosition(1.0), np.zeros(3), nav)[1], _rows(m, GnssVelocity(1.0), np.zeros(3), nav)[1]])
    S = np.ones(m.n)
    S[m.slices["lever_arm"]] = -1.0
    H_aids = H[[1, 0, 2, 3, 4, 5]] * S
    colmax = np.abs(H_chen).max(0) + 1e-300
    assert np.max(np.abs(H_chen - H_aids) / colmax) < 1e-12
    assert np.count_nonzero(H_chen) == np.count_nonzero(H_aids) > 30


# ----------------------------------------------------------------------------- against a dense update

def _still(seconds=20.0):
    """An IMU at rest at 45°N for ``seconds`` (100 Hz)."""
    return tr.generate([tr.Dwell(seconds)], 45 * DEG, 110 * DEG, 300.0, dt=0.01)


class _Dense:
    """The textbook batch Kalman update (Gelb 1974, table 4.2-1; Joseph form): S = H P⁻ Hᵀ + R,
    K = P⁻ Hᵀ S⁻¹, x̂ = K z, P⁺ = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ."""

    def __init__(self, P, H, R):
        self.P, self.H, self.R = P, H, R

    def update(self, z):
        S = self.H @ self.P @ self.H.T + self.R
        Kg = np.linalg.solve(S, self.H @ self.P).T
        A = np.eye(len(self.P)) - Kg @ self.H
        self.x = Kg @ z
        self.P = A @ self.P @ A.T + Kg @ self.R @ Kg.T


def _first_update(m, aid, traj, st0, q0, H, Rm):
    """The filter's first epoch (after 10 IMU steps) beside the dense update of the same prior.

    The prior P⁻ is the filter's own covariance propagated without measurements (``prior_covariance``:
    at the first epoch it is P⁻), z the residual it recorded; :class:`_Dense` gives P⁺ and x̂ = K z."""
    ep = np.array([10, 20])
    rec = nf.run_filter(m, (aid,), nf.Imu(traj.t[:21], traj.dtheta[:20], traj.dv[:20]), (st0[None], q0[None]), ep,
                        options=nf.Options(store_P=True, prior_covariance=True, workers=1))
    kf = _Dense(rec.P_bar[0].copy(), H, Rm)
    z = rec.innov[0, 0, :H.shape[0]]
    kf.update(z)
    return rec, kf, z


def test_zero_velocity_update_is_the_dense_kalman_update():
    """ZUPT (3 rows, z = v̂ = δv + w) against the dense update.  Tolerance: the filter's sequential scalar
    updates equal the batch update in exact arithmetic; 15 states in double precision agree to
    1e-9 of the largest variance, and the fed-back velocity v⁺ = v̂ − δv̂ to 1e-9 m/s."""
    traj = _still()
    m = er.model_15(lat=traj.lat[0], h=traj.h[0], velocity_sd=0.5)
    init = traj.initial_state()
    st0 = init.vector() + np.array([0, 0, 0, 0.3, -0.2, 0.1])
    R = np.array([1e-4, 1e-4, 4e-4])
    H = np.zeros((3, m.n))
    H[:, 3:6] = np.eye(3)
    rec, kf, z = _first_update(m, ZeroVelocity(R), traj, st0, dcm_to_quat(init.C_bn), H, np.diag(R))
    assert np.max(np.abs(rec.P[0] - kf.P)) < 1e-9 * np.max(np.diag(kf.P))
    assert np.allclose(rec.st[0, 0, 3:6], z - kf.x[3:6], rtol=0, atol=1e-9)


def test_barometric_height_is_the_dense_kalman_update():
    """Baro height (1 row, z = ĥ − h(p) + b̂ = δh − b + w) with a barometer bias state against
    the dense update; the pressure is the standard atmosphere's at the true height minus 10 m of bias.
    Tolerances as for the ZUPT; the estimated bias is x̂_b (b̂ starts at zero)."""
    traj = _still()
    baro = er.StateBlock("baro", ("b",), "none", dynamics=np.zeros((1, 1)), noise_psd=np.zeros((1, 1)),
                         sd=np.array([20.0]))
    m = er.model_15(lat=traj.lat[0], h=traj.h[0]).extend(baro)
    col = m.slices["baro"].start
    p = 101325.0 * (1 - 0.0065 * (traj.h[[10, 20]] - 10.0) / 288.15) ** (9.80665 / (287.05287 * 0.0065))
    assert np.allclose(pressure_height(p), traj.h[[10, 20]] - 10.0, atol=1e-6)
    init = traj.initial_state()
    H = np.zeros((1, m.n))
    H[0, 2], H[0, col] = 1.0, -1.0
    rec, kf, z = _first_update(m, BaroHeight(4.0, col, p), traj, init.vector(), dcm_to_quat(init.C_bn), H,
                               np.array([[4.0]]))
    assert np.max(np.abs(rec.P[0] - kf.P)) < 1e-9 * np.max(np.diag(kf.P))
    assert np.isclose(rec.p_hat[0, 0, col - 9], kf.x[col], rtol=0, atol=1e-9)
    assert np.isclose(rec.st[0, 0, 2], z[0] + pressure_height(p[0]) - kf.x[2], rtol=0, atol=1e-6)


def test_zero_velocity_holds_a_still_imu():
    """Over 20 s at rest with a 0.3 m/s initial velocity error, 10-Hz ZUPTs (σ 0.01 m/s) bring
    every velocity error under 0.03 m/s (3 σ of the aid)."""
    traj = _still()
    m = er.model_15(lat=traj.lat[0], h=traj.h[0], velocity_sd=0.5)
    init = traj.initial_state()
    st0 = init.vector() + np.array([0, 0, 0, 0.3, -0.2, 0.1])
    ep = np.arange(10, traj.n + 1, 10)
    rec = nf.run_filter(m, (ZeroVelocity(1e-4),), nf.Imu(traj.t, traj.dtheta, traj.dv),
                        (st0[None], dcm_to_quat(init.C_bn)[None]), ep, options=nf.Options(workers=1))
    assert np.max(np.abs(rec.st[0, -1, 3:6])) < 0.03


# ----------------------------------------------------------------------------- a new aid

AID = '''
"""A vertical-velocity aid (e.g. a barometric rate): one row v̂_U − v_U,aid = δv_U."""
import numpy as np
from replication.nav.measurements import CTX_ST, Measurement, compile_residual, compile_rows


@compile_rows
def _rows(par, data, ctx, c, enc, H, Rd, r):
    H[r, 5] = 1.0
    Rd[r] = par[0]
    return 1


@compile_residual
def _residual(par, data, ctx, c, z, m):
    z[m] = ctx[CTX_ST + 5] - data[0]
    return 1


class VerticalVelocity(Measurement):
    size = 1
    width = 1
    rows_kernel = _rows
    residual_kernel = _residual

    def __init__(self, R, values):
        self.R = float(R)
        super().__init__(np.asarray(values, float)[:, None])

    def parameters(self, model):
        return np.array([self.R])
'''


def test_an_aid_is_one_module_written_elsewhere(tmp_path):
    """An aid is one module outside the package, passed to the façade with no other edit, and the
    compiled loop is not compiled again for it (its signatures are unchanged).  The filter, fed the
    true vertical velocity offset by 0.5 m/s, pulls the INS's vertical velocity onto the aid:
    60 s of 10-Hz updates with a 0.01 m/s aid σ settle the 0.5 m/s step to well under 0.05 m/s."""
    (tmp_path / "vertical_velocity_aid.py").write_text(textwrap.dedent(AID), encoding="utf-8")
    spec = importlib.util.spec_from_file_location("vertical_velocity_aid", tmp_path / "vertical_velocity_aid.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    try:
        spec.loader.exec_module(mod)
    finally:
        sys.modules.pop(spec.name, None)
    traj = tr.generate([tr.Climb(60.0, height_change=120.0)], 45 * DEG, 110 * DEG, 1000.0, dt=0.01, speed=100.0)
    m = er.model_15(lat=traj.lat[0], h=traj.h[0], velocity_sd=0.5)
    ep = np.arange(10, traj.n + 1, 10)
    init = traj.initial_state()
    imu = nf.Imu(traj.t, traj.dtheta, traj.dv)
    nf.run_filter(m, (GnssVelocity(1e-4, traj.v_enu[ep]),), imu, init, ep, options=nf.Options(workers=1))
    compiled = len(cl.filter_chunk.signatures)
    out = {}
    for offset in (0.0, 0.5):
        aid = mod.VerticalVelocity(1e-4, traj.v_enu[ep, 2] + offset)
        rec = nf.run_filter(m, (aid,), imu, init, ep, options=nf.Options(workers=1))
        out[offset] = rec.st[0, -1, 5] - traj.v_enu[-1, 2]
    assert abs(out[0.0]) < 0.05 and abs(out[0.5] - 0.5) < 0.05
    assert len(cl.filter_chunk.signatures) == compiled


def test_measurements_are_checked():
    """Bad aids and values are refused with the name of what is wrong."""
    m = _model()
    with pytest.raises(ValueError, match="positive variances"):
        GnssPosition([1.0, -1.0, 1.0])
    with pytest.raises(ValueError, match="augmented states"):
        AirHeight(1.0, 3).parameters(m)
    with pytest.raises(ValueError, match="values must be"):
        GnssVelocity(1.0, np.zeros((5, 2)))
    with pytest.raises(ValueError, match="pressures must be positive"):
        BaroHeight(1.0, pressure=[-1.0])
    with pytest.raises(TypeError, match="Measurement"):
        cl.build_spec(m, measurements=("gnss",))
    with pytest.raises(ValueError, match="1..8 measurements"):
        cl.build_spec(m, measurements=(ZeroVelocity(1.0),) * 9)
    traj = _still(1.0)
    with pytest.raises(ValueError, match="has no values"):
        nf.run_filter(m, (GnssPosition(1.0),), nf.Imu(traj.t, traj.dtheta, traj.dv), traj.initial_state(), [10])
    assert issubclass(ZeroVelocity, Measurement)
