"""chen2019 Table 2-2: the printed sub-blocks of the error-state matrix F, and the same blocks from
the package's model.

The report prints F of its 45-state model (eqs. (2-14)/(2-15)) block by block in Table 2-2.  This
module evaluates the printed blocks at a navigation point (:func:`table_2_2_printed`), their
corrected form (:func:`table_2_2_corrected`), the blocks of the model of
:mod:`replication.papers.chen2019.models` at the same point (:func:`table_2_2_verified`, from a
numerical Jacobian of the mechanization) and the differences block by block
(:func:`table_2_2_differences`).
"""

from __future__ import annotations

import math

import numpy as np

from replication.nav import earth
from replication.nav import errors as E
from replication.nav._kernels import KIND_MISALIGN, coupling_matrix
from replication.nav._validate import positive
from replication.nav.rotations import euler_to_dcm, skew
from replication.papers.chen2019 import models as M

_SECONDS = M._SECONDS


def _nav_quantities(point):
    lat, h = float(point.lat), float(point.h)
    rm, rn = earth.radii(lat)
    ve, vn, vu = (float(x) for x in point.v_enu)
    fn = np.asarray(point.C_bn, float) @ np.asarray(point.f_b, float)
    return dict(L=lat, h=h, Rm=rm + h, Rn=rn + h, VE=ve, VN=vn, VU=vu, w=earth.OMEGA_IE, s=math.sin(lat),
                c=math.cos(lat), t=math.tan(lat), sec=1 / math.cos(lat), fE=fn[0], fN=fn[1], fU=fn[2])


TABLE_2_2_BLOCKS = ("F11", "F12", "F21", "F22", "F23", "F31", "F32", "F33", "F41", "F42", "F43", "F51", "F52",
                    "F53", "F6", "F7")
"""The printed sub-blocks of chen2019 Table 2-2's F (F33/F41 are printed twice, identically)."""


def table_2_2_reference_point():
    """A generic evaluation point for the Table 2-2 comparison.

    The chen2019 flight conditions (47°N, 115°E, 6000 m, heading ≈ 45°) with a climb
    (v_U = 5 m/s), bank, and non-zero components of f^b and ω_ib^b, so that no printed element
    vanishes by accident.

    Returns
    -------
    point : replication.nav.errors.NavPoint
        Latitude and longitude [rad], height [m], v_enu [m/s], C_bn, f_b [m/s²], w_ib_b [rad/s].
    """
    return E.NavPoint(math.radians(47.0), math.radians(115.0), 6000.0, np.array([70.7, 68.0, 5.0]),
                      euler_to_dcm(0.7, 0.05, 0.17), np.array([0.3, -0.4, 9.7]), np.array([0.01, -0.02, 0.03]))


def table_2_2_printed(point, *, accel_markov_tau=3600.0, gyro_markov_tau=3600.0) -> dict:
    """The sub-blocks of chen2019 Table 2-2 *as printed*, evaluated at ``point``.

    In the report's conventions (gyro errors with +C_b^n).  Reading of the damaged print
    (data/paper/chen2019/chen2019-table-2-2.csv): the single "(R_n+h)^2" under the third column of
    F21 is the denominator of all three third-column entries; F42's five garbled rows are the
    fractions [[0, -1/(R_m+h), 0], [1/(R_n+h), 0, 0], [tan L/(R_n+h), 0, 0]]; the "-f_N" printed
    at F22(3,3) is kept where printed; F32/F33 fill the six misalignment columns in the text's
    state order (A_xy, A_yx, A_xz, A_zx, A_yz, A_zy); F6 = diag(-1/α), F7 = diag(-1/β) with α, β
    the Markov correlation times.

    Parameters
    ----------
    point : replication.nav.errors.NavPoint
        Evaluation point: latitude [rad], longitude [rad], height [m], v_enu [m/s], C_bn,
        f_b [m/s²], w_ib_b [rad/s].
    accel_markov_tau : float
        Correlation time α of the accelerometer Markov bias [s].
    gyro_markov_tau : float
        Correlation time β of the gyro Markov drift [s].

    Returns
    -------
    blocks : dict of str to ndarray, shape (3, 3)
        Name of :data:`TABLE_2_2_BLOCKS` -> the 3×3 block in SI units (rad, m, m/s, s).

    Raises
    ------
    ValueError
        When a correlation time is not positive.
    """
    q = _nav_quantities(point)
    Rm, Rn, VE, VN, VU, w, s, c, t, sec = (q[k] for k in ("Rm", "Rn", "VE", "VN", "VU", "w", "s", "c", "t", "sec"))
    fE, fN, fU = q["fE"], q["fN"], q["fU"]
    C = np.asarray(point.C_bn, float)
    f = np.asarray(point.f_b, float)
    om = np.asarray(point.w_ib_b, float)
    B = {}
    B["F11"] = np.array([[0, 0, -VN / Rm**2], [VE * sec * t / Rn, 0, -VE * sec / Rn**2], [0, 0, 0]])
    B["F12"] = np.array([[0, 1 / Rm, 0], [sec / Rn, 0, 0], [0, 0, 1]])
    B["F21"] = np.array([[2 * w * (c * VN + s * VU) + VE * VN * sec**2 / Rn, 0, VE * (VU - VN * t) / Rn**2],
                         [-2 * w * c * VE - VE**2 * sec**2 / Rn, 0, (VE**2 * t + VN * VU) / Rn**2],
                         [-2 * w * s * VE, 0, (VE**2 + VN**2) / Rn**2]])
    B["F22"] = np.array([[(VN * t - VU) / Rm, 2 * w * s + VE * t / Rn, -2 * w * c - VE / Rn],
                         [-2 * (w * s + VE * t / Rn), -VU / Rm, -VN / Rm],
                         [2 * w * c + VE / Rn, -2 * VN / Rm, -fN]])
    B["F23"] = np.array([[0, -fU, -fN], [fU, 0, -fE], [fE, 0, 0]])
    B["F31"] = C * f[None, :]
    B["F32"] = np.column_stack([C[:, 0] * f[1], C[:, 1] * f[0], C[:, 0] * f[2]])
    B["F33"] = np.column_stack([C[:, 2] * f[0], C[:, 1] * f[2], C[:, 2] * f[1]])
    B["F41"] = np.array([[0, 0, VN / Rm**2], [-w * s, 0, -VE / Rn**2], [w * c + VE * sec**2 / Rn, 0, -VE * t / Rn**2]])
    B["F42"] = np.array([[0, -1 / Rm, 0], [1 / Rn, 0, 0], [t / Rn, 0, 0]])
    B["F43"] = np.array([[0, w * s + VE * t / Rn, -w * c - VE / Rn], [-w * s - VE / Rn, 0, -VN / Rm],
                         [w * c + VE / Rn, VN / Rm, 0]])
    B["F51"] = C * om[None, :]
    B["F52"] = np.column_stack([C[:, 0] * om[1], C[:, 1] * om[0], C[:, 0] * om[2]])
    B["F53"] = np.column_stack([C[:, 2] * om[0], C[:, 1] * om[2], C[:, 2] * om[1]])
    B["F6"] = -np.eye(3) / positive(accel_markov_tau, "accel_markov_tau", _SECONDS)
    B["F7"] = -np.eye(3) / positive(gyro_markov_tau, "gyro_markov_tau", _SECONDS)
    return B


def table_2_2_corrected(point, *, accel_markov_tau=3600.0, gyro_markov_tau=3600.0) -> dict:
    """The Table 2-2 sub-blocks re-derived, evaluated at ``point``.

    Same conventions and the same approximation level as the report: Earth radii and gravity
    frozen, gyro errors with +C_b^n.  Verified against :func:`~replication.papers.chen2019.models.frozen_earth_jacobian` and
    ``ErrorModel.F`` in tests/test_models.py; :data:`replication.papers.chen2019.findings.TABLE_2_2_CORRECTED_TEXT` gives the
    expressions::

        F21(·,3) = [V_E(V_U - V_N tan L)/(R_N+h)², V_E² tan L/(R_N+h)² + V_N V_U/(R_M+h)²,
                    -V_E²/(R_N+h)² - V_N²/(R_M+h)²];  F22(1,1) = (V_N tan L - V_U)/(R_N+h),
        F22(3,·) = [2ω_ie cos L + 2V_E/(R_N+h), 2V_N/(R_M+h), 0];  F23 = (f^n ×);
        F32/F33 = C_b^n ∂(δA f^b)/∂(A_xy, A_yx, A_xz, A_zx, A_yz, A_zy) (eq. (2-8));
        F43(2,1) = -ω_ie sin L - V_E tan L/(R_N+h);  the others as printed.

    Parameters
    ----------
    point : replication.nav.errors.NavPoint
        Evaluation point: latitude [rad], longitude [rad], height [m], v_enu [m/s], C_bn,
        f_b [m/s²], w_ib_b [rad/s].
    accel_markov_tau : float
        Correlation time α of the accelerometer Markov bias [s].
    gyro_markov_tau : float
        Correlation time β of the gyro Markov drift [s].

    Returns
    -------
    blocks : dict of str to ndarray, shape (3, 3)
        Name of :data:`TABLE_2_2_BLOCKS` -> the 3×3 block in SI units.

    Raises
    ------
    ValueError
        When a correlation time is not positive.
    """
    B = table_2_2_printed(point, accel_markov_tau=accel_markov_tau, gyro_markov_tau=gyro_markov_tau)
    q = _nav_quantities(point)
    Rm, Rn, VE, VN, VU, w, s, c, t = (q[k] for k in ("Rm", "Rn", "VE", "VN", "VU", "w", "s", "c", "t"))
    B["F21"][:, 2] = [VE * (VU - VN * t) / Rn**2, VE**2 * t / Rn**2 + VN * VU / Rm**2, -VE**2 / Rn**2 - VN**2 / Rm**2]
    B["F22"][0, 0] = (VN * t - VU) / Rn
    B["F22"][2, :] = [2 * w * c + 2 * VE / Rn, 2 * VN / Rm, 0.0]
    B["F23"] = skew(np.array([q["fE"], q["fN"], q["fU"]]))
    C = np.asarray(point.C_bn, float)
    Bm = np.empty((3, 6))
    coupling_matrix(KIND_MISALIGN, np.asarray(point.f_b, float), Bm)
    B["F32"], B["F33"] = (C @ Bm)[:, :3], (C @ Bm)[:, 3:]
    coupling_matrix(KIND_MISALIGN, np.asarray(point.w_ib_b, float), Bm)
    B["F52"], B["F53"] = (C @ Bm)[:, :3], (C @ Bm)[:, 3:]
    B["F43"][1, 0] = -w * s - VE * t / Rn
    return B


def table_2_2_verified(model, point) -> dict:
    """The Table 2-2 sub-blocks taken from the verified matrices, in the report's conventions.

    Navigation blocks from :func:`~replication.papers.chen2019.models.frozen_earth_jacobian` (finite differences of the mechanization,
    the report's approximation level), sensor blocks from ``model.F`` (checked against
    ``ErrorModel.numerical_jacobian``) with the gyro-error columns negated (+C_b^n convention of
    eq. (2-15)), Markov dynamics from the model.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        A 45-state model of :func:`~replication.papers.chen2019.models.model_45`.
    point : replication.nav.errors.NavPoint
        Evaluation point: latitude [rad], longitude [rad], height [m], v_enu [m/s], C_bn,
        f_b [m/s²], w_ib_b [rad/s].

    Returns
    -------
    blocks : dict of str to ndarray, shape (3, 3)
        Name of :data:`TABLE_2_2_BLOCKS` -> the 3×3 block in SI units.

    Raises
    ------
    TypeError
        When ``model`` is not an ``ErrorModel``.
    ValueError
        When ``model`` lacks a block of the 45-state model.
    """
    M._check_model(model)
    need = set(M.CHEN2019_45_ORDER)
    if not need <= {b.name for b in model.blocks}:
        raise ValueError("table_2_2_verified needs the 45-state model (models.model_45())")
    J = M.frozen_earth_jacobian(point)
    F = model.F(point)
    s = model.slices
    B = {"F11": J[0:3, 0:3], "F12": J[0:3, 3:6], "F21": J[3:6, 0:3], "F22": J[3:6, 3:6], "F23": J[3:6, 6:9],
         "F41": J[6:9, 0:3], "F42": J[6:9, 3:6], "F43": J[6:9, 6:9]}
    am = F[3:6, s["accel_misalignment"]]
    gm = -F[6:9, s["gyro_misalignment"]]
    B.update(F31=F[3:6, s["accel_scale"]], F32=am[:, :3], F33=am[:, 3:], F51=-F[6:9, s["gyro_scale"]],
             F52=gm[:, :3], F53=gm[:, 3:], F6=F[s["accel_markov"], s["accel_markov"]],
             F7=F[s["gyro_markov"], s["gyro_markov"]])
    return {k: np.array(v) for k, v in B.items()}


def table_2_2_differences(model, point, *, rtol=1e-6, floor=1e-8) -> list:
    """Element-wise comparison of the printed Table 2-2 blocks with the verified ones at ``point``.

    ``differs`` means abs(printed - verified) > rtol · abs(verified) + floor · max abs(verified
    block).  Defaults: well above the accuracy of the verified blocks (the finite differences of
    :func:`~replication.papers.chen2019.models.frozen_earth_jacobian` agree with the re-derived expressions of
    :func:`table_2_2_corrected` to 3e-9 of the block scale, tests/test_models.py) and far below the
    smallest erratum (1e-2 relative); the Markov time constants of the printed F6/F7 are taken from
    ``model``.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        A 45-state model of :func:`~replication.papers.chen2019.models.model_45`.
    point : replication.nav.errors.NavPoint
        Evaluation point: latitude [rad], longitude [rad], height [m], v_enu [m/s], C_bn,
        f_b [m/s²], w_ib_b [rad/s].
    rtol : float
        Relative tolerance per element [1].
    floor : float
        Absolute tolerance as a fraction of the verified block's largest element [1].

    Returns
    -------
    rows : list of dict
        One per element of every block of :data:`TABLE_2_2_BLOCKS`: ``block`` (str), ``row``,
        ``col`` (int, 1-based), ``printed``, ``verified`` (float, SI units), ``differs`` (bool).
    """
    F = M._check_model(model).F(point)
    s = model.slices
    ta = -1.0 / F[s["accel_markov"], s["accel_markov"]][0, 0]
    tg = -1.0 / F[s["gyro_markov"], s["gyro_markov"]][0, 0]
    P = table_2_2_printed(point, accel_markov_tau=ta, gyro_markov_tau=tg)
    V = table_2_2_verified(model, point)
    out = []
    for name in TABLE_2_2_BLOCKS:
        p, v = P[name], V[name]
        scale = np.abs(v).max()
        for i in range(p.shape[0]):
            for j in range(p.shape[1]):
                d = abs(p[i, j] - v[i, j])
                out.append(dict(block=name, row=i + 1, col=j + 1, printed=float(p[i, j]), verified=float(v[i, j]),
                                differs=bool(d > rtol * abs(v[i, j]) + floor * scale)))
    return out
