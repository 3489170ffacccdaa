"""PWCS / SVD observability degree on systems with known answers; covariance cross-check."""

import numpy as np
import pytest

from replication.nav import trajectory as tr
from replication.nav.sensors import ImuErrors, TriadErrors
from replication.papers.chen2019 import findings, maneuvers, observability_tables, scenarios
from replication.papers.chen2019 import models as M
from replication.papers.chen2019 import observability as O

G, R = 9.8, 6.4e6


def switching_bias(s):
    """x' = b1 + s b2, b1' = b2' = 0, y = x: the sign s of the second input switches between
    segments (a textbook piece-wise constant system)."""
    F = np.array([[0.0, 1.0, s], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    H = np.array([[1.0, 0.0, 0.0]])
    return F, H


def test_decoupled_system_degrees_are_the_output_gains():
    """F = 0, H = diag(a): Q = [diag(a); 0; 0], σ_k = |a_k| assigned to state k."""
    a = np.array([3.0, -0.5, 2e-3, 40.0])
    d = O.observability_degrees(O.observability_matrix(np.zeros((4, 4)), np.diag(a)))
    assert np.allclose(d.degree, np.abs(a), rtol=1e-14)
    assert list(d.index) == [1, 2, 3, 0]            # σ sorted: 40, 3, 0.5, 2e-3
    assert d.rank == 4


def test_switching_bias_one_segment_is_unobservable_two_are_not():
    """One segment: rank 2, null direction (0, 1, -1)/√2 (b1 and b2 indistinguishable).
    Two segments s = +1, -1: SOM columns are orthogonal with norm √2 → every σ = √2;
    the Goshen-Meskin condition holds, so rank TOM = rank SOM = 3."""
    F1, H1 = switching_bias(1.0)
    F2, H2 = switching_bias(-1.0)
    Q1 = O.observability_matrix(F1, H1)
    d1 = O.observability_degrees(Q1)
    assert d1.rank == 2
    null = d1.V[:, 2]
    assert np.allclose(np.abs(null), [0, 1 / np.sqrt(2), 1 / np.sqrt(2)], atol=1e-12)
    assert O.som_condition(F1, H1)
    Qs = O.stripped_observability_matrix([(F1, H1), (F2, H2)])
    d2 = O.observability_degrees(Qs)
    assert np.allclose(d2.singular_values, np.sqrt(2), rtol=1e-14)
    assert np.allclose(d2.degree, np.sqrt(2), rtol=1e-14)
    Qt = O.total_observability_matrix([(F1, H1), (F2, H2)], [1.0, 2.0])
    assert np.linalg.matrix_rank(Qt) == np.linalg.matrix_rank(Qs) == 3


def test_stationary_single_axis_ins():
    """One horizontal channel of a stationary INS (Goshen-Meskin & Bar-Itzhack 1992):
    δv' = -g φ + ∇, φ' = δv/R + ε, y = δv.  Rank 3 of 4; the unobservable direction is
    (0, 1, g, 0) (a tilt balancing the accelerometer bias), so the bias — the larger component
    of that null vector — gets the zero singular value; the gyro drift is observable."""
    F = np.array([[0.0, -G, 1.0, 0.0], [1 / R, 0.0, 0.0, 1.0], [0.0] * 4, [0.0] * 4])
    H = np.array([[1.0, 0.0, 0.0, 0.0]])
    d = O.observability_degrees(O.observability_matrix(F, H), labels=["dv", "phi", "bias", "drift"])
    assert d.rank == 3
    null = d.V[:, 3] * np.sign(d.V[1, 3])
    assert np.allclose(null, np.array([0, 1, G, 0]) / np.hypot(1, G), atol=1e-9)
    assert d.degree[2] < d.rank_tol                    # zero to the numerical-rank tolerance
    assert d.observable().tolist() == [True, True, False, True]
    # the drift's degree: its column H F² e_ε = -g is orthogonal to the others at leading order
    assert abs(d.degree[3] - G) / G < 1e-3


def test_states_with_identical_columns_share_the_larger_degree_whatever_the_round_off():
    """Two states entering Q through the same column are split evenly between a singular vector
    with σ > 0 and one with σ = 0: which one argmax picks would be decided by round-off.  The tie
    goes to the larger σ, for every order of the columns and under tiny perturbations."""
    rng = np.random.default_rng(3)
    base = np.linalg.qr(rng.standard_normal((12, 3)))[0] * np.array([3.0, 2.0, 1.0])  # orthogonal columns
    Q = np.column_stack([base, base[:, 1]])          # state 3 duplicates state 1: σ = 2√2 and 0
    ref = O.observability_degrees(Q)
    assert ref.degree[1] == pytest.approx(ref.degree[3], rel=1e-12) == pytest.approx(2 * np.sqrt(2))
    # split evenly: maximal ambiguity; the others lie in one direction only
    assert ref.ambiguity[[1, 3]] == pytest.approx([1.0, 1.0]) and np.all(ref.ambiguity[[0, 2]] < 1e-9)
    for trial in range(20):
        perm = rng.permutation(4)
        Qp = Q[:, perm] * (1 + 1e-14 * rng.standard_normal(Q[:, perm].shape))
        for assignment in ("state", "singular"):
            d = O.observability_degrees(Qp, assignment=assignment)
            pos = [int(np.flatnonzero(perm == k)[0]) for k in (1, 3)]
            assert d.degree[pos[0]] == pytest.approx(d.degree[pos[1]], rel=1e-9)
            assert d.degree[pos[0]] == pytest.approx(2 * np.sqrt(2), rel=1e-9)


def test_a_repeated_singular_value_is_assigned_by_its_subspace_not_by_an_arbitrary_basis():
    """chen2019 before the maneuver: φ_E ≡ δA_zy and φ_N ≡ δA_zx enter through columns of equal
    norm, so σ = 2√2 is repeated and its singular vectors are any rotation within the plane; the
    entry of one vector is then round-off, the projection onto the plane is not."""
    rng = np.random.default_rng(5)
    for trial in range(20):
        e = np.linalg.qr(rng.standard_normal((10, 2)))[0] * 2.0
        Q = np.column_stack([e[:, 0], e[:, 1], e[:, 0], e[:, 1]])
        Q = Q * (1 + 1e-14 * rng.standard_normal(Q.shape))
        d = O.observability_degrees(Q)
        assert np.allclose(d.degree, 2 * np.sqrt(2), rtol=1e-9), d.degree


def test_normalizations_and_sign_invariance():
    rng = np.random.default_rng(7)
    Q = rng.standard_normal((30, 5)) * np.array([1.0, 10.0, 0.1, 3.0, 1e-3])
    d = O.observability_degrees(Q)
    dm = O.observability_degrees(Q, normalize="max")
    assert dm.degree.max() <= 1.0 and np.allclose(dm.degree, d.degree / d.singular_values[0])
    s = np.array([2.0, 0.5, 1.0, 4.0, 100.0])
    ds = O.observability_degrees(Q, normalize="scale", state_scale=s)
    assert np.allclose(ds.degree, O.observability_degrees(Q * s).degree)
    # flipping the sign of a state (e.g. the gyro-error convention) changes no degree
    flip = np.array([1, -1, 1, -1, 1])
    assert np.allclose(O.observability_degrees(Q * flip).degree, d.degree, rtol=1e-12)
    dsg = O.observability_degrees(Q, assignment="singular")
    assert set(dsg.degree[dsg.index >= 0]) <= set(dsg.singular_values)


def test_spearman():
    assert observability_tables.spearman([1, 2, 3, 4], [10, 20, 30, 40]) == pytest.approx(1.0)
    assert observability_tables.spearman([1, 2, 3, 4], [4, 3, 2, 1]) == pytest.approx(-1.0)


@pytest.fixture(scope="module")
def flight():
    _, init = scenarios.chen2019_flight()
    return tr.generate([tr.Straight(60.0), tr.Turn(120.0, np.pi)], dt=0.5, **init)


def test_pwcs_on_the_45_state_model_straight_flight(flight):
    """Straight level flight (one constant segment): the gyro x/y drifts are seen through the
    tilt they build (column H F² e_ε, H F³ e_ε of norm √2 g with the position in metres), the
    sum ∇_z + g δK_az only through δK_az, the accelerometer x/y scale factors not at all (f_x = f_y
    ≈ 0 up to the Coriolis residual)."""
    m = M.model_45()
    keep = m.labels[:9] + M.table_2_3_states()[3:]
    d = O.pwcs_observability(m, flight, [(0.0, 60.0)], states=keep)
    deg = d.as_dict()
    g = 9.79
    for s in ("gyro_bias.x", "gyro_bias.y"):
        assert abs(deg[s] / (np.sqrt(2) * g) - 1) < 5e-3
    assert deg["accel_scale.z"] > 10 and deg["accel_bias.z"] <= d.rank_tol * 10
    assert deg["accel_scale.y"] <= d.rank_tol * 10
    # the turn adds segments: observability of heading (φ_U) appears
    d2 = O.pwcs_observability(m, flight, [(0.0, 60.0)] + O.segment_bounds(60.0, 180.0, 6), states=keep)
    assert d2.as_dict()["phiU"] > 1.0 > 1e3 * deg["phiU"]


def test_covariance_observability(flight):
    """√(P0/P): the unexcited accelerometer y scale factor (f_y = 0 at constant speed) keeps
    its prior to 1e-3; velocity errors, measured directly with σ = 0.03 m/s against a prior
    of 1 m/s, shrink by far more than 10."""
    sd = ImuErrors(accel=TriadErrors(bias=5e-4, scale=1e-5, misalignment=1e-5, markov_tau=3600.0),
                   gyro=TriadErrors(bias=5e-8, scale=1e-5, misalignment=1e-5, markov_tau=3600.0))
    m = M.model_45(imu_sd=sd, velocity_sd=1.0)
    keep = m.labels[:9] + M.table_2_3_states()[3:]
    Rm = np.diag([0.03**2, 0.03**2, 0.1**2, 0.03**2, 0.03**2, 0.03**2])
    r = O.covariance_observability(m, flight, 0.0, 180.0, update_interval=2.0, R=Rm, states=keep)
    rr = dict(zip(keep, r))
    assert abs(rr["accel_scale.y"] - 1) < 1e-3
    assert min(rr["dvE"], rr["dvN"], rr["dvU"]) > 10


def test_bad_inputs():
    with pytest.raises(ValueError, match="square"):
        O.observability_matrix(np.zeros((2, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="columns"):
        O.observability_matrix(np.zeros((3, 3)), np.zeros((1, 2)))
    with pytest.raises(ValueError, match="n_powers"):
        O.observability_matrix(np.zeros((3, 3)), np.zeros((1, 3)), n_powers=0)
    with pytest.raises(ValueError, match="finite"):
        O.observability_degrees(np.array([[np.nan, 1.0]]))
    with pytest.raises(ValueError, match="assignment"):
        O.observability_degrees(np.eye(2), assignment="max")
    with pytest.raises(ValueError, match="state_scale"):
        O.observability_degrees(np.eye(2), normalize="scale")
    with pytest.raises(ValueError, match="n_segments"):
        O.segment_bounds(0.0, 1.0, 0)
    with pytest.raises(ValueError, match="durations"):
        O.total_observability_matrix([(np.zeros((2, 2)), np.eye(2))], [0.0])
    with pytest.raises(ValueError, match="at least one"):
        O.stripped_observability_matrix([])
    with pytest.raises(TypeError, match="ErrorModel"):
        O.piecewise_systems("model", None, [(0, 1)])
    with pytest.raises(ValueError, match="spearman"):
        observability_tables.spearman([1, 2], [2, 1])


def test_series_discretization_matches_expm(flight):
    """The covariance recursion's order-8 series (Φ, Q_d) equals Van Loan's expm to 1e-9 of
    the largest element over a 2 s interval in a turn (F's products decay through the 1/R
    couplings: the truncated terms are below (ω_s T)^8 / 8!)."""
    from replication.nav import errors as E
    from replication.nav.kalman import discretize_series, van_loan
    sd = ImuErrors(accel=TriadErrors(markov_sigma=1e-4, markov_tau=3600.0, white_psd=1e-8),
                   gyro=TriadErrors(markov_sigma=1e-8, markov_tau=3600.0, white_psd=1e-14))
    m = M.model_45(imu_sd=sd, gravity_sigma=1e-4)
    p = E.NavPoint.from_trajectory(flight, 200)
    F, Qc = m.F(p), m.G_Qc(p.C_bn)
    P1, Q1 = discretize_series(F, Qc, 2.0, 8)
    P2, Q2 = van_loan(F, Qc, 2.0)
    assert np.abs(P1 - P2).max() <= 1e-9 * np.abs(P2).max()
    assert np.abs(Q1 - Q2).max() <= 1e-9 * np.abs(Q2).max()


def test_chen2019_maneuvers_and_tables():
    mv = maneuvers.chen2019_maneuvers(u_turn=100.0, figure_eight=200.0, s_turn=200.0, straight=20.0, total=260.0, dt=1.0)
    assert list(mv) == list(maneuvers.CHEN2019_MANEUVERS)
    assert all(abs(m.traj.t[-1] - 260.0) < 1e-9 for m in mv.values())
    # headings: the U-turn reverses the course, the figure-8 and the S-turn return to it
    h = {k: np.degrees(m.traj.hpr[int(m.t_end), 0]) % 360 for k, m in mv.items()}
    assert h["U-turn"] == pytest.approx(225.0, abs=1e-6)
    assert h["figure-8"] == pytest.approx(45.0, abs=1e-6) and h["S-turn"] == pytest.approx(45.0, abs=1e-6)
    assert mv["before maneuver"].spans(8) == [(0.0, 20.0)]
    assert len(mv["U-turn"].spans(8, 2)) == 10
    m = M.model_45()
    st = m.labels[:9] + M.table_2_3_states()[3:]
    df = observability_tables.degrees_table(m, mv, states=st, n_segments=4)
    assert df.shape == (33, 4) and set(df.attrs["rank_tol"]) == set(maneuvers.CHEN2019_MANEUVERS)
    met = observability_tables.rank_metrics(df, df, reference_threshold=1e-5, reproduced_threshold=1e-5)
    assert np.allclose(met["spearman"], 1.0) and (met["verdicts_agree"] == 33).all()
    best = observability_tables.best_scenario_counts(df)
    assert list(best.index) == ["U-turn", "figure-8", "S-turn"]
    # a state whose largest degree is shared (zero everywhere: never excited) counts for none
    shared = int(((df.iloc[:, 1:] == df.iloc[:, 1:].max(axis=1).to_numpy()[:, None]).sum(axis=1) > 1).sum())
    assert best.sum() == 33 - shared and shared >= 1
    with pytest.raises(ValueError, match="total"):
        maneuvers.chen2019_maneuvers(total=10.0)
    with pytest.raises(ValueError, match="same states"):
        observability_tables.rank_metrics(df, df.iloc[:5], reference_threshold=1e-5, reproduced_threshold=1e-5)


def test_goshen_meskin_condition_on_the_45_state_segments():
    """Along a U-turn every segment's unobservable directions are not moved by F (|F N| at
    rounding level), so the SOM has the rank of the TOM; a system violating it is detected."""
    mv = maneuvers.chen2019_maneuvers(u_turn=100.0, figure_eight=200.0, s_turn=200.0, straight=20.0, dt=1.0)
    m = M.model_45()
    st = m.labels[:9] + M.table_2_3_states()[3:]
    sy = O.piecewise_systems(m, mv["U-turn"].traj, mv["U-turn"].spans(4), states=st)
    assert all(O.som_condition(F, H) for F, H in sy)
    # counter-example: nothing is measured (H = 0), yet F moves x1 with the unobservable x2
    F = np.array([[0.0, 1.0], [0.0, 0.0]])
    H = np.array([[0.0, 0.0]])
    assert O.som_condition(F, H) is False


def test_rank_uses_the_documented_tolerance():
    """rank and observable() share one rule, σ_max · max(m, n) · ε.  A tall Q (m = 1000, n = 2)
    whose second singular value is 5e-14 σ_max lies between 10 n ε (4.4e-15) and m ε (2.2e-13):
    numerically zero under the documented rule, so the rank is 1 for every normalization."""
    rng = np.random.default_rng(7)
    u, _ = np.linalg.qr(rng.standard_normal((1000, 2)))
    Q = u @ np.diag([1.0, 5e-14])
    for norm in (None, "max"):
        d = O.observability_degrees(Q, normalize=norm)
        assert d.rank == 1
        assert list(d.observable()) == [True, False]
    d = O.observability_degrees(Q, normalize="scale", state_scale=[2.0, 3.0])
    assert d.rank == 1


def test_coordinated_turns_leave_no_lateral_specific_force():
    """observability.coordinated: the bank absorbs the ~0.01 m/s² Coriolis/transport residual of a
    kinematically banked turn (f_x below 1e-9 m/s², round-off of the rotation), f^n unchanged to
    round-off, and the roll changes by less than 0.1° (0.0119/9.8 rad ≈ 0.07°)."""
    mv = maneuvers.chen2019_maneuvers(u_turn=100.0, figure_eight=200.0, s_turn=200.0, straight=20.0, total=260.0, dt=1.0)
    t = mv["U-turn"].traj
    c = maneuvers.coordinated(t)
    assert np.abs(t.f_b[:, 0]).max() > 1e-3                       # the residual is there before
    assert np.abs(c.f_b[:, 0]).max() < 1e-9
    f_n, f_n_c = (np.einsum("kij,kj->ki", x.C_bn, x.f_b) for x in (t, c))
    assert np.abs(f_n - f_n_c).max() < 1e-12
    assert np.degrees(np.abs(c.hpr[:, 2] - t.hpr[:, 2]).max()) < 0.1


def test_verdict_under_decides_with_a_round_off_margin():
    assert observability_tables.verdict_under(2.0, 5.0, 1e-9, 0.1) == (True, True, True)
    # a degree within a decade of the rank tolerance is round-off: unobservable
    assert observability_tables.verdict_under(1e-18, 5e-9, 1e-9, 0.1) == (False, False, True)
    assert observability_tables.verdict_under(3.0, 5e-9, 1e-9, 0.1) == (True, False, True)
    # verdicts differ but the assignment is ambiguous: no verdict
    assert observability_tables.verdict_under(3.0, 0.0, 1e-9, 0.99)[2] is False
    with pytest.raises(ValueError, match="degree"):
        observability_tables.verdict_under(1.0, float("nan"), 1e-9, 0.1)


def _degrees(values, tol=1e-9, amb=0.1):
    import pandas as pd
    values = {k: v + [0.0] for k, v in values.items()}                 # a third state, unobservable everywhere
    t = pd.DataFrame(values, index=["a", "b", "c"], columns=["before maneuver", "turn"])
    t.attrs["rank_tol"] = {c: tol for c in t.columns}
    t.attrs["ambiguity"] = {c: {s: amb for s in t.index} for c in t.columns}
    return t


def _sandbox(tmp_path, monkeypatch):
    """A throw-away project root (tables/ and the notebook the rows name) so compare() writes nothing real."""
    (tmp_path / "tables").mkdir()
    (tmp_path / "data" / "paper" / "chen2019").mkdir(parents=True)
    (tmp_path / "book").mkdir()
    (tmp_path / "book" / "x.ipynb").write_text("{}", encoding="utf-8")
    monkeypatch.setenv("REPLICATION_ROOT", str(tmp_path))


def test_compare_verdicts_rows_declare_their_basis_and_the_ledger_decides(tmp_path, monkeypatch):
    """A verdict that differs under the main reading is a 'verdict' row that does not agree; the registry
    then derives: unverifiable when a reading not ruled out reaches it and keeps the rest of its printed
    column, inconsistent when every reaching reading loses another value of the column, not-reproduced
    when none reaches it; a ruled-out reading never rescues a row."""
    from replication.registry import audit
    from replication.registry import reproduction as rp
    _sandbox(tmp_path, monkeypatch)
    printed = _degrees({"before maneuver": [1.0, 1e-20], "turn": [2.0, 3.0]})
    printed.loc["c", "turn"], printed.loc["d"] = 1e-20, [1e-20, 2.0]                  # c null in the turn; d observable
    main = _degrees({"before maneuver": [1.0, 0.0], "turn": [0.0, 0.0]}).reindex(printed.index, fill_value=0.0)
    other = main.copy(); other.loc["b", "turn"] = 4.0                                  # reaches b, keeps the column
    lossy = main.copy(); lossy.loc[["a", "c"], "turn"] = 5.0                           # reaches a, loses c
    old = main.copy(); old.loc[["a", "b", "d"], "turn"] = 5.0                          # reaches all, ruled out
    for t in (main, other, lossy, old):
        t.attrs = {"rank_tol": {c: 1e-9 for c in t.columns},
                   "ambiguity": {c: dict.fromkeys(t.index, 0.1) for c in t.columns}}
    exact = {(s, c): printed.loc[s, c] > 1e-5 and c == "before maneuver" for s in printed.index for c in printed.columns}
    rows, ledger = findings.compare_verdicts(printed, {"main": main, "other": other, "lossy": lossy, "old convention": old},
                                             "main", exact=exact, explain=dict.fromkeys("abcd", "why"), ruled_out=["old"])
    assert {r["basis"] for r in rows} == {"verdict"}
    assert {r["quantity"]: r["agrees"] for r in rows if r["quantity"].endswith("turn")} == {
        "a | turn": False, "b | turn": False, "c | turn": True, "d | turn": False}
    # the ledger: every reading but the main one (and the second computation) on every value
    assert len(ledger) == 4 * len(rows) and not any(q["quantity"].startswith("main |") for q in ledger)
    assert any(q["quantity"].startswith(findings.EXACT_READING) for q in ledger)
    rp.compare("chen2019-check-table-9-9-readings", ledger, notebook="book/x.ipynb", title="ledger")
    group_of = {q: g for g, qs in findings.column_groups(printed).items() for q in qs}
    rows = [dict(r, group=group_of.get(r["quantity"])) for r in rows]
    t = rp.compare("chen2019-table-9-9", rows, notebook="book/x.ipynb", title="main", main_reading="main",
                   reading_evidence="the printed 2.0", ruled_out={"old": "the printed 2.0"}).set_index("quantity").status
    assert t["a | turn"] == "inconsistent" and "loses c" in next(r["note"] for r in rows if r["quantity"] == "a | turn")
    assert t["b | turn"] == "unverifiable" and "'other'" in next(r["note"] for r in rows if r["quantity"] == "b | turn")
    assert t["c | turn"] == "qualitative"
    assert t["d | turn"] == "not-reproduced"                                           # only the ruled-out reading reaches it
    assert all("ruled_out" in p.reason or "quotes no printed value" in p.reason
               for p in audit.audit(["chen2019-table-9-9", "chen2019-check-table-9-9-readings"]))
    # a differing value on which the main reading gives no verdict (ambiguous assignment) is 'unstated'
    amb = main.copy(); amb.attrs = {"rank_tol": main.attrs["rank_tol"],
                                    "ambiguity": {c: dict.fromkeys(main.index, 0.99) for c in main.columns}}
    rows2, _ = findings.compare_verdicts(printed, {"main": amb}, "main", exact=exact, explain=dict.fromkeys("abcd", "why"))
    assert next(r for r in rows2 if r["quantity"] == "a | turn")["basis"] == "unstated"
    with pytest.raises(ValueError, match="ruled out"):
        findings.compare_verdicts(printed, {"old": main}, "old", exact=exact, explain={}, ruled_out=["old"])


def test_one_threshold_for_tables_sweep_and_verdicts():
    """degrees_table, sweep and verdict_under share one threshold, ROUND_OFF_MARGIN times the rank tolerance."""
    assert O.verdict_threshold(2e-5) == pytest.approx(2e-4)
    assert O.verdict_threshold({"a": 1e-9}) == {"a": pytest.approx(1e-8)}
    mv = maneuvers.chen2019_maneuvers(u_turn=100.0, figure_eight=200.0, s_turn=200.0, straight=20.0, dt=1.0)
    m = M.model_45(misalignment_coupling="table-2-2")
    st = m.labels[:9] + M.table_2_3_states()[3:]
    raw = observability_tables.degrees_table(m, mv, states=st, n_segments=4, clip_null=False)
    df = observability_tables.degrees_table(m, mv, states=st, n_segments=4)
    for c in df.columns:
        thr = df.attrs["threshold"][c]
        assert thr == pytest.approx(O.ROUND_OFF_MARGIN * df.attrs["rank_tol"][c])
        assert ((raw[c] > thr) == (df[c] > 0)).all()                                   # reported 0 at or below it
        assert all(observability_tables.verdict_under(1.0, d, df.attrs["rank_tol"][c], 0.1)[1] == (d > thr) for d in raw[c])
    sens = observability_tables.sweep(m, mv, df, {"same": dict(n_segments=4)}, states=st, progress=False)
    assert [int(sens.loc["same", f"observable {c}"]) for c in df.columns] == [int((df[c] > 0).sum()) for c in df.columns]


def test_speed_wave_excites_the_forward_axis():
    """A speed wave of A m/s over a T-s turn gives a forward specific force f_y up to πA/T (plus
    round-off), zero at constant speed, and the speed returns to its start."""
    kw = dict(u_turn=100.0, figure_eight=200.0, s_turn=200.0, straight=20.0, dt=0.5)
    const, wave = maneuvers.chen2019_maneuvers(**kw), maneuvers.chen2019_maneuvers(speed_wave=2.0, **kw)
    t = wave["U-turn"].traj
    assert np.abs(const["U-turn"].traj.f_b[:, 1]).max() < 1e-9
    assert np.abs(t.f_b[:, 1]).max() == pytest.approx(np.pi * 2.0 / 100.0, rel=2e-3)
    speed = np.hypot(t.v_enu[:, 0], t.v_enu[:, 1])
    assert speed.max() == pytest.approx(102.0, abs=1e-6) and speed[-1] == pytest.approx(100.0, abs=1e-9)
    assert np.degrees(t.hpr[-1, 0]) % 360 == pytest.approx(225.0, abs=1e-6)
    with pytest.raises(ValueError, match="stop"):
        tr.generate([tr.Turn(10.0, 1.0, speed_wave=-200.0)], 0.8, 2.0, 100.0, speed=100.0, dt=1.0)


def test_constant_rate_turn_holds_its_rate_between_the_ramps():
    """SteadyTurn: ψ̇ = angle / (T - ramp) between the ramps, the full heading change at the end,
    continuous heading and rate at the ramp ends; flown, the body z rate varies only by the Earth and
    transport rates as the heading turns (< 0.5 %)."""
    turn = tr.SteadyTurn(100.0, np.pi, ramp=10.0)
    tau = np.linspace(0.0, 100.0, 2001)
    dpsi, rate, _ = turn.heading(tau)
    mid = (tau >= 10.0) & (tau <= 90.0)
    assert np.allclose(rate[mid], np.pi / 90.0, rtol=1e-12, atol=0.0)
    assert dpsi[-1] == pytest.approx(np.pi, abs=1e-12) and rate[0] == 0.0 and rate[-1] == pytest.approx(0.0, abs=1e-15)
    assert np.max(np.abs(np.diff(dpsi))) < 2 * np.pi / 90.0 * 0.05
    t = tr.generate([tr.Straight(10.0), turn, tr.Straight(10.0)], 0.8, 2.0, 6000.0, speed=100.0, dt=0.5)
    w = t.w_ib_b[(t.t >= 25.0) & (t.t <= 95.0), 2]
    assert np.ptp(w) < 5e-3 * np.abs(w).mean()
    const = maneuvers.chen2019_maneuvers(u_turn=100.0, figure_eight=200.0, s_turn=200.0, straight=20.0, dt=0.5, turn_rate="constant")
    assert np.degrees(const["figure-8"].traj.hpr[-1, 0]) % 360 == pytest.approx(45.0, abs=1e-6)
    assert np.degrees(const["S-turn"].traj.hpr[-1, 0]) % 360 == pytest.approx(45.0, abs=1e-6)
    with pytest.raises(ValueError, match="ramp"):
        tr.SteadyTurn(10.0, 1.0, ramp=6.0)
    with pytest.raises(ValueError, match="turn_rate"):
        maneuvers.chen2019_maneuvers(turn_rate="steady")
    with pytest.raises(ValueError, match="bank"):
        maneuvers.chen2019_maneuvers(bank="flat")


def test_maneuver_only_interval_and_the_flight_grid():
    mv = maneuvers.chen2019_maneuvers(u_turn=100.0, figure_eight=200.0, s_turn=200.0, straight=20.0, dt=1.0)
    assert mv["U-turn"].spans(4, 0)[0][0] == 20.0 and len(mv["U-turn"].spans(4, 0)) == 4
    assert mv["before maneuver"].spans(4, 0) == [(0.0, 20.0)]           # the straight scenario has nothing else
    with pytest.raises(ValueError, match="before_segments"):
        mv["U-turn"].spans(4, -1)
    fl = maneuvers.flight_readings(speed_wave=2.0, base=mv, u_turn=100.0, figure_eight=200.0, s_turn=200.0, straight=20.0, dt=1.0)
    assert len(fl) == 16 and next(iter(fl)) == "V const, ramped rate, banked, with straight leg"
    assert fl["V const, ramped rate, banked, with straight leg"]["maneuvers"] is mv
    assert fl["V wave 2 m/s, constant rate, unbanked, maneuver only"]["before_segments"] == 0
    assert np.abs(fl["V wave 2 m/s, ramped rate, unbanked, maneuver only"]["maneuvers"]["U-turn"].traj.hpr[:, 2]).max() == 0.0
    with pytest.raises(ValueError, match="speed_wave"):
        maneuvers.flight_readings(speed_wave=0.0)


def test_spearman_critical_value():
    """The two-sided 5 % critical value of Spearman's ρ for 27 pairs is 0.381 (t approximation)."""
    assert observability_tables.spearman_critical(27) == pytest.approx(0.381, abs=5e-4)
    assert observability_tables.spearman_critical(27, 0.01) > observability_tables.spearman_critical(27)
    with pytest.raises(ValueError):
        observability_tables.spearman_critical(2)
    with pytest.raises(ValueError, match="alpha"):
        observability_tables.spearman_critical(27, 1.5)
