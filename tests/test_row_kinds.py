"""The measurement row kinds of the closed-loop filter (replication.nav.closedloop.ROW_KINDS).

Each kind writes its rows of H and their variances for the lead (``_kind_rows``) and its
residuals for every run (``_kind_residuals``), in one module; these tests hold every registered
kind to its registered number of rows, its rows to the derivative of its residuals, and the
chen2019 measurement matrix to the GNSS kinds."""

import ast
import inspect
from pathlib import Path

import numpy as np
import pytest

from replication.nav import _kernels as K
from replication.nav import closedloop as cl
from replication.nav import errors as er
from replication.nav import trajectory as tr
from replication.nav.rotations import rotvec_to_dcm
from replication.nav.units import DEG
from replication.papers.chen2019 import models as M

PKG = Path(__file__).resolve().parents[1] / "replication"


def _setting():
    """A 15-state model with a lever arm and two air-data error states, a spec using every kind,
    a chunk's inputs of one epoch whose aids agree with the INS state ``st``, and the lead's window
    sums."""
    air = er.StateBlock("air", ("h", "V"), "none", dynamics=-np.eye(2) / 300.0, noise_psd=np.eye(2) * 1e-3,
                        sd=np.array([1.0, 0.5]))
    m = er.model_15(lat=0.8, h=3000.0).extend(er.lever_arm(0.1), air)
    col = m.slices["air"].start
    spec = cl.build_spec(m, gnss=cl.GnssRows(np.diag([0.01, 0.02, 0.03]), np.diag([1e-4, 2e-4, 3e-4])),
                         rows=(("air_height", col, 1.0), ("airspeed", col + 1, 0.25)))
    st = np.array([0.8, 2.0, 3000.0, 80.0, -40.0, 2.0])
    c = rotvec_to_dcm(np.array([0.05, -0.03, 1.1]))
    lever = np.array([0.4, -1.2, 2.5])
    w = (0.01, -0.02, 0.15)
    # the GNSS fix at the antenna and the air data where the INS puts them
    rm, rn = K.radii_s(st[0])
    la = c @ lever
    gpos = np.array([st[0] + la[1] / (rm + st[2]), st[1] + la[0] / ((rn + st[2]) * np.cos(st[0])), st[2] + la[2]])
    gvel = st[3:6] + c @ np.cross(w, lever)
    aux = np.array([[[st[2], np.linalg.norm(st[3:6])]]])
    inp = cl.chunk_inputs(np.full(1, 0.01), np.zeros((1, 1, 3)), np.zeros((1, 1, 3)), [0],
                          gnss=(gpos[None, None], gvel[None, None]), windows=(np.ones(1), np.zeros(1, np.int64), np.zeros(1, np.int64),
                                                          np.array([[0.1, -0.2, 0.3]]), np.array([[1e-4, 1e-4, 1e-4]])),
                          aux=aux, n_aug=m.n - 9)
    lead = cl.LeadState(np.eye(m.n), np.eye(m.n), np.array([0.1, 0.2, 9.8]), np.zeros((6, m.n)))
    return m, spec, inp, lead, (c, lever, *w, st)


def _rows(spec, inp, lead, nav, i, sf=0):
    """The rows of the ``i``-th kind of ``spec`` alone."""
    c, lever, wx, wy, wz, st = nav
    H = np.zeros((9, spec.fconst.shape[0]))
    Rd = np.zeros(9)
    m = cl._kind_rows(spec.rows[i:i + 1], spec.row_R[i:i + 1], spec.row_col[i:i + 1], sf, inp.sf_R, lead.facc,
                      lead.Cw, spec.sf_H, spec.tg, spec.bs, spec.bz, c, lever, wx, wy, wz, st, H, Rd)
    return m, H[:m], Rd[:m]


def _residuals(spec, inp, nav, i, p_hat):
    """The residuals of the ``i``-th kind of ``spec`` alone (run 0, epoch 0)."""
    c, lever, wx, wy, wz, st = nav
    z = np.zeros(9)
    m = cl._kind_residuals(spec.rows[i:i + 1], spec.row_col[i:i + 1], spec.row_aux[i:i + 1], 0, inp.sf_a,
                           np.array([0.1, -0.2, 0.3]), inp.gpos[0, 0], inp.gvel[0, 0], inp.aux[0, 0], p_hat, c, lever,
                           wx, wy, wz, st, z)
    return m, z[:m]


def test_every_registered_kind_writes_its_rows_and_residuals():
    """Every kind of ``ROW_KINDS`` has a branch in both dispatchers writing its registered number of
    rows, with the variances given to ``build_spec``; a kind registered without them fails here."""
    m, spec, inp, lead, nav = _setting()
    size = {code: k for code, k in cl.ROW_KINDS.values()}
    assert sorted(spec.rows) == sorted(size)              # the setting uses every kind
    for i, code in enumerate(spec.rows):
        mr, H, Rd = _rows(spec, inp, lead, nav, i)
        assert mr == size[code] and np.all(np.any(H != 0, axis=1))
        assert _residuals(spec, inp, nav, i, np.zeros(m.n - 9))[0] == size[code]
        if code in (cl.ROW_GNSS_POSITION, cl.ROW_GNSS_VELOCITY, cl.ROW_AIR_HEIGHT, cl.ROW_AIRSPEED):
            assert np.array_equal(Rd, spec.row_R[i, :mr])
        else:
            assert np.array_equal(Rd, inp.sf_R[0])
    # no measurement of the specific force where no window ends
    assert _rows(spec, inp, lead, nav, list(spec.rows).index(cl.ROW_SPECIFIC_FORCE), sf=-1)[0] == 0


def test_row_kinds_live_in_one_module():
    """A kind is registered and dispatched in ``replication.nav.closedloop`` alone: its code constant
    appears in both dispatchers there and in no other module of the package."""
    names = [f"ROW_{name.upper()}" for name in cl.ROW_KINDS]
    for name in names:
        assert getattr(cl, name) == cl.ROW_KINDS[name[4:].lower()][0]
    for fn in (cl._kind_rows, cl._kind_residuals):
        src = inspect.getsource(fn.py_func)
        used = {n.id for n in ast.walk(ast.parse(src)) if isinstance(n, ast.Name)}
        assert set(names) <= used, f"{fn.py_func.__name__} lacks a branch for {set(names) - used}"
    for path in PKG.rglob("*.py"):
        if path.name == "closedloop.py" and path.parent.name == "nav":
            continue
        text = path.read_text(encoding="utf-8")
        assert not any(name in text for name in names), f"{path} refers to a row kind's code"


@pytest.mark.parametrize("kind", ["gnss_position", "gnss_velocity", "air_height", "airspeed"])
def test_rows_are_the_derivative_of_the_residuals(kind):
    """Where the aid agrees with the INS, H's navigation columns are the derivative of the kind's
    residual with respect to the INS state [L, λ, h, v] (an INS error δx moves the residual by
    H δx), and its error-state column (−1: INS minus aid) the negative of the derivative with
    respect to the accumulated estimate.  Central differences, steps 1e-3 of each state's scale:
    the residuals are at most quadratic in the step, so 1e-6 column-relative leaves room for the
    curvature of the Earth's radii and for rounding."""
    m, spec, inp, lead, nav = _setting()
    i = list(spec.rows).index(cl.ROW_KINDS[kind][0])
    mr, H, _ = _rows(spec, inp, lead, nav, i)
    c, lever, wx, wy, wz, st = nav
    scale = np.array([1e-6, 1e-6, 1.0, 0.1, 0.1, 0.1])
    J = np.empty((mr, 6))
    for k in range(6):
        d = np.zeros(6)
        d[k] = 1e-3 * scale[k]
        zp = _residuals(spec, inp, (c, lever, wx, wy, wz, st + d), i, np.zeros(m.n - 9))[1]
        zm = _residuals(spec, inp, (c, lever, wx, wy, wz, st - d), i, np.zeros(m.n - 9))[1]
        J[:, k] = (zp - zm) / (2 * d[k])
    colmax = np.maximum(np.abs(J).max(0), np.abs(H[:, :6]).max(0)) + 1e-300
    assert np.max(np.abs(H[:, :6] - J) / colmax) < 1e-6
    col = spec.row_col[i]
    if col >= 0:
        p = np.zeros(m.n - 9)
        p[col - 9] = 0.7
        dz = (_residuals(spec, inp, nav, i, p)[1] - _residuals(spec, inp, nav, i, np.zeros(m.n - 9))[1]) / 0.7
        assert np.allclose(dz, -H[:, col], rtol=0, atol=1e-12) and np.all(H[:, col] == -1.0)


def test_chen2019_measurement_matrix_is_the_gnss_kind():
    """chen2019 eq. (2-13) as ``models.measurement_matrix`` writes it and the filter's GNSS kinds
    are one measurement: H_chen2019(l) = P H_kinds(−l) S, exactly to rounding (1e-12 of each
    column), where

    * P orders the rows as chen2019's Z: north, east, up (the kinds: east, north, up), then the
      velocity rows E, N, U;
    * the lever arm has the opposite sense: chen2019 carries the fix from the antenna to the SINS
      centre (SINS centre = antenna + C l), the kinds from the IMU to the antenna
      (antenna = IMU + C l), so the kinds are evaluated with −l;
    * S = −1 on the three lever-arm states (each side's δl is true minus used of its own vector),
      +1 on every other state (δp, δv, φ in the same sense: INS minus true, Ĉ = exp(−φ×) C)."""
    traj = tr.generate([tr.Straight(5.0), tr.Turn(10.0, np.pi / 2)], 47 * DEG, 115 * DEG, 3000.0,
                       heading=30 * DEG, speed=100.0, dt=0.01)
    m = M.model_45()
    p = er.NavPoint.from_trajectory(traj, 1200)
    lever = np.array([0.4, -1.2, 2.5])
    H_chen = M.measurement_matrix(m, p, lever)
    _, _, tg, _, bs, _ = m.kernel_encoding()
    C = np.asarray(p.C_bn, float)
    w = M._w_eb_b(p)
    H = np.zeros((6, m.n))
    K.gnss_position_rows(H, 0, C, -lever, p.lat, p.h, tg, bs)
    K.gnss_velocity_rows(H, 3, C, -lever, *w, tg, bs)
    S = np.ones(m.n)
    S[m.slices["lever_arm"]] = -1.0
    H_kinds = H[[1, 0, 2, 3, 4, 5]] * S
    colmax = np.abs(H_chen).max(0) + 1e-300
    assert np.max(np.abs(H_chen - H_kinds) / colmax) < 1e-12
    assert np.count_nonzero(H_chen) == np.count_nonzero(H_kinds) > 30


def test_a_new_kind_is_one_module_and_its_test(tmp_path):
    """A new kind touches ``closedloop`` alone: its registry entry and one branch in each dispatcher.
    Here a vertical-velocity aid (v̂_U − v_U,aid = δv_U, e.g. a barometric rate) is added to a copy
    of the module by exactly those three edits, and the copy's filter, fed the true vertical
    velocity offset by 0.5 m/s, pulls the INS's vertical velocity onto the aid: the demonstration
    that nothing else (the builder, the driver, ``build_spec``'s checks) needs to know the kind.
    Tolerance: 60 s of 10-Hz updates with a 0.01 m/s aid σ settle the 0.5 m/s step to well under
    0.05 m/s (the velocity's σ after the first update is about 0.01 m/s)."""
    import importlib.util
    import sys

    from replication.nav.rotations import dcm_to_quat

    src = (PKG / "nav" / "closedloop.py").read_text(encoding="utf-8")
    edits = [
        ('"airspeed": (4, 1)}', '"airspeed": (4, 1), "vertical_velocity": (5, 1)}'),
        ('ROW_AIRSPEED = ROW_KINDS["airspeed"][0]\n',
         'ROW_AIRSPEED = ROW_KINDS["airspeed"][0]\nROW_VERTICAL_VELOCITY = ROW_KINDS["vertical_velocity"][0]\n'),
        ("            Rd[r] = row_R[i, 0]\n            r += 1\n",
         "            Rd[r] = row_R[i, 0]\n            r += 1\n"
         "        elif kind == ROW_VERTICAL_VELOCITY:\n            H[r, 5] = 1.0\n"
         "            Rd[r] = row_R[i, 0]\n            r += 1\n"),
        ("            z[m] = v\n            m += 1\n",
         "            z[m] = v\n            m += 1\n"
         "        elif kind == ROW_VERTICAL_VELOCITY:\n            z[m] = st[5] - aux[row_aux[i]]\n            m += 1\n"),
    ]
    for old, new in edits:
        assert src.count(old) == 1, old
        src = src.replace(old, new)
    path = tmp_path / "closedloop_with_a_kind.py"
    path.write_text(src, encoding="utf-8")
    spec_ = importlib.util.spec_from_file_location("closedloop_with_a_kind", path)
    demo = importlib.util.module_from_spec(spec_)
    sys.modules[spec_.name] = demo                    # dataclasses resolve annotations through it
    try:
        spec_.loader.exec_module(demo)
    finally:
        sys.modules.pop(spec_.name, None)
    assert src.count("ROW_VERTICAL_VELOCITY") == 3                      # registry, two branches

    traj = tr.generate([tr.Climb(60.0, height_change=120.0)], 45 * DEG, 110 * DEG, 1000.0, dt=0.01, speed=100.0)
    m = er.model_15(lat=traj.lat[0], h=traj.h[0], velocity_sd=0.5)
    spec = demo.build_spec(m, rows=(("vertical_velocity", None, 1e-4),))
    ep = np.arange(10, traj.n + 1, 10)
    init = traj.initial_state()
    out = {}
    for offset in (0.0, 0.5):
        aux = (traj.v_enu[ep, 2] + offset)[None, :, None]
        state = demo.initial_batch_state(init.vector()[None], dcm_to_quat(init.C_bn)[None], np.zeros(3))
        rec = demo.run(spec, state, m.P0(), ep, traj.n,
                       demo.array_inputs(traj.t, traj.dtheta[None], traj.dv[None], ep, aux=aux, n_aug=m.n - 9),
                       options=demo.Options(workers=1))
        out[offset] = rec.st[0, -1, 5] - traj.v_enu[-1, 2]
    assert abs(out[0.0]) < 0.05 and abs(out[0.5] - 0.5) < 0.05
    with pytest.raises(ValueError, match="vertical_velocity"):
        cl.build_spec(m, rows=(("vertical_velocity", None, 1e-4),))       # the package's module has no such kind

