"""Error-state models built from named blocks: the 15-state model and its extensions.

State vector: the 9 navigation errors, always first,

    [δL, δλ, δh | δv_E, δv_N, δv_U | φ_E, φ_N, φ_U]     (rad, rad, m | m/s | rad)

followed by *augmented blocks*, each a named slice with its own linear dynamics and a coupling
into the navigation equations.  Definitions (consistent with :mod:`replication.nav.rotations`):

* navigation errors are computed minus true: δL = L̂ - L, δv = v̂ - v, Ĉ_b^n = (I - φ×) C_b^n;
* an augmented state is the true value of an error source minus the value currently compensated
  (so that in closed loop the estimate is simply accumulated: p̂ ← p̂ + x̂).

Continuous model (chen2019 eqs. (3-14)-(3-16), every first-order term kept — including the
normal-gravity gradient ∂γ/∂h, ∂γ/∂L and dR_M/dL, dR_N/dL, which the printed F omits):

    δṗ = F_pp δp + F_pv δv
    δv̇ = f^n × φ - (2ω_ie^n + ω_en^n) × δv + v^n × (2δω_ie^n + δω_en^n) + δg_γ(δp) + C_b^n δf^b - x_g
    φ̇ = -ω_in^n × φ + δω_in^n - C_b^n δω_ib^b

with the sensor errors of chen2019 eq. (2-10), δu = Σ_blocks B_kind(u) x_block:
``identity`` (random constant ε_b/∇_b, first-order Markov ε_m/∇_m: B = I), ``scale``
(δK: B = diag(u)) and ``misalignment`` (δG/δA of eq. (2-8): six angles).  x_g is a gravity-
disturbance block (eq. (2-12) shaping filter).  The sign of the gyro term follows from the
definitions above; chen2019 (3-16) prints +C_b^n ε (ε counted with the opposite sign) and
(3-15) prints ψ × f^n where its own F23 block is (f^n ×) ψ = f^n × ψ, used here.

Build models with :func:`model_15` or by composing blocks::

    m15 = model_15(accel_bias_sd=..., gyro_bias_sd=..., accel_psd=..., gyro_psd=...)
    m = m15.extend(accel_markov(...), gyro_markov(...), accel_scale(...), gyro_scale(...),
                   accel_misalignment(...), gyro_misalignment(...), gravity_shaping(...),
                   lever_arm(...))
    m.slices["gyro_bias"], m.labels, m.F(point), m.numerical_jacobian(point)
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from replication.nav import _kernels as K
from replication.nav import earth
from replication.nav._validate import (
    choice,
    covariance,
    finite_array,
    finite_result,
    nonnegative_array,
    numeric,
    positive,
    rotation,
    series_order,
    vector3,
)
from replication.nav.rotations import euler_to_dcm, rotvec_to_dcm
from replication.nav.strapdown import NavState, navigation_rates
from replication.nav.trajectory import Trajectory

__all__ = ["StateBlock", "ErrorModel", "NavPoint", "nav_block_labels", "accel_bias", "gyro_bias",
           "accel_markov", "gyro_markov", "accel_scale", "gyro_scale", "accel_misalignment",
           "gyro_misalignment", "gravity_shaping", "lever_arm", "model_15", "NAV_LABELS", "MISALIGNMENT_COUPLINGS"]

NAV_LABELS = ("dL", "dlon", "dh", "dvE", "dvN", "dvU", "phiE", "phiN", "phiU")
_TARGETS = {"accel": K.TARGET_ACCEL, "gyro": K.TARGET_GYRO, "gravity": K.TARGET_GRAVITY,
            "lever_arm": K.TARGET_LEVER, "none": K.TARGET_NONE}
_KINDS = {"identity": K.KIND_IDENTITY, "scale": K.KIND_SCALE, "misalignment": K.KIND_MISALIGN,
          "misalignment-cross-axis": K.KIND_MISALIGN_CROSS}
MISALIGNMENT_COUPLINGS = {"axis-angles": "misalignment", "cross-axis": "misalignment-cross-axis"}
"""How the six misalignment parameters [xy, yx, xz, zx, yz, zy] couple: axis angles, δC = [[0, -yz, zy],
[xz, 0, -zx], [-xy, yx, 0]] (chen2019 eq. (2-8)), or cross-axis coefficients, δC = [[0, xy, xz], [yx, 0, yz],
[zx, zy, 0]] (chen2019 Table 2-2's F32/F33, F52/F53)."""
_MIS_LABELS = ("xy", "yx", "xz", "zx", "yz", "zy")


def nav_block_labels():
    """Labels of the 9 navigation error states, ``NAV_LABELS`` as a list.

    Returns
    -------
    labels : list of str
        ``["dL", "dlon", "dh", "dvE", "dvN", "dvU", "phiE", "phiN", "phiU"]``.
    """
    return list(NAV_LABELS)


@dataclass(frozen=True)
class StateBlock:
    """One augmented block of the error state.

    Attributes
    ----------
    name : str
        Unique key (``"accel_bias"``, ``"gyro_markov"``, ...).
    labels : tuple of str
        One label per component; their number k is the block's size.
    target : {"accel", "gyro", "gravity", "lever_arm", "none"}
        What it perturbs: ``"accel"`` (f^b), ``"gyro"`` (ω_ib^b), ``"gravity"`` (g^n),
        ``"lever_arm"`` (GNSS antenna offset, measurement only) or ``"none"``.
    kind : {"identity", "scale", "misalignment", "misalignment-cross-axis"}
        Coupling B(u) for accel/gyro targets: ``"identity"``, ``"scale"`` or a misalignment
        (:data:`MISALIGNMENT_COUPLINGS`); default ``"identity"``.  An identity or scale block has
        3 states, a misalignment block 6.
    dynamics : ndarray, shape (k, k)
        Matrix A of ẋ = A x + w [1/s] (zeros, the default: random constant).
    noise_psd : ndarray, shape (k, k)
        Intensity of w [state unit²/s], symmetric positive semi-definite; default zeros.
    output : ndarray, shape (3, k) or None
        Matrix mapping the block to δg^n (gravity blocks; default the first three states);
        None for other targets.
    sd : ndarray, shape (k,)
        Initial standard deviations [state units] (for P0 and for drawing truth values); default
        zeros.
    fd_step : float
        Finite-difference step [state units] for the numerical Jacobian, default 1e-6.

    Raises
    ------
    ValueError
        For an unknown target or kind, a number of labels the kind does not allow, or a matrix of
        the wrong shape, not finite, or a negative intensity or standard deviation.
    """

    name: str
    labels: tuple
    target: str
    kind: str = "identity"
    dynamics: np.ndarray | None = None
    noise_psd: np.ndarray | None = None
    output: np.ndarray | None = None
    sd: np.ndarray | None = None
    fd_step: float = 1e-6

    def __post_init__(self):
        k = len(self.labels)
        if self.target not in _TARGETS:
            raise ValueError(f"block {self.name!r}: target must be one of {sorted(_TARGETS)}, got {self.target!r}")
        if self.kind not in _KINDS:
            raise ValueError(f"block {self.name!r}: kind must be one of {sorted(_KINDS)}, got {self.kind!r}")
        need = {"identity": 3, "scale": 3, "misalignment": 6, "misalignment-cross-axis": 6}[self.kind]
        if self.target in ("accel", "gyro") and k != need:
            raise ValueError(f"block {self.name!r}: a {self.kind} block has {need} states, got {k} labels")
        if self.target == "lever_arm" and k != 3:
            raise ValueError(f"block {self.name!r}: a lever-arm block has 3 states")
        for attr, shape in (("dynamics", (k, k)), ("noise_psd", (k, k)), ("sd", (k,))):
            val = getattr(self, attr)
            arr = np.zeros(shape) if val is None else numeric(val, f"block {self.name!r}: {attr}")
            if arr.shape != shape:
                raise ValueError(f"block {self.name!r}: {attr} must have shape {shape}, got {arr.shape}")
            object.__setattr__(self, attr, arr)
        finite_array(self.dynamics, f"block {self.name!r}: dynamics")
        covariance(self.noise_psd, f"block {self.name!r}: noise_psd")
        _variances(self.sd, f"block {self.name!r}: sd")
        if self.target == "gravity":
            out = np.eye(3, k) if self.output is None else np.asarray(self.output, float)
            if out.shape != (3, k):
                raise ValueError(f"block {self.name!r}: output must be 3×{k}")
            object.__setattr__(self, "output", out)

    @property
    def size(self):
        """Number k of states of the block."""
        return len(self.labels)


@dataclass
class NavPoint:
    """A point of a trajectory at which F is evaluated: nav state and true sensor outputs.

    Attributes
    ----------
    lat : float
        Geodetic latitude [rad].
    lon : float
        Longitude [rad].
    h : float
        Ellipsoidal height [m].
    v_enu : ndarray, shape (3,)
        Velocity (East, North, Up) [m/s].
    C_bn : ndarray, shape (3, 3)
        Attitude DCM C_b^n.
    f_b : ndarray, shape (3,)
        Specific force, body axes [m/s²].
    w_ib_b : ndarray, shape (3,)
        Angular rate ω_ib^b, body axes [rad/s].
    """

    lat: float
    lon: float
    h: float
    v_enu: np.ndarray
    C_bn: np.ndarray
    f_b: np.ndarray
    w_ib_b: np.ndarray

    def validate(self, *, name: str = "point"):
        """Check the fields as :meth:`replication.nav.strapdown.NavState.validate` does.

        Also checks finite f_b and w_ib_b; raises naming the field (the compiled F checks nothing).

        Parameters
        ----------
        name : str, optional
            Name of the point in the error messages, default ``"point"``.

        Returns
        -------
        point : NavPoint
            ``self``, unchanged.

        Raises
        ------
        ValueError
            Naming the first invalid field.
        """
        NavState.validate(self, name=name)
        vector3(self.f_b, f"{name}.f_b")
        vector3(self.w_ib_b, f"{name}.w_ib_b")
        return self

    @classmethod
    def from_trajectory(cls, traj, k: int):
        """The point at sample ``k`` of a trajectory.

        Parameters
        ----------
        traj : Trajectory
            A trajectory (:func:`replication.nav.trajectory.generate`).
        k : int
            Sample index.

        Returns
        -------
        point : NavPoint
            Its position, velocity, attitude C_b^n (from ``hpr``), f^b and ω_ib^b at sample ``k``.
        """
        return cls(float(traj.lat[k]), float(traj.lon[k]), float(traj.h[k]), traj.v_enu[k].copy(),
                   euler_to_dcm(*traj.hpr[k]),
                   traj.f_b[k].copy(), traj.w_ib_b[k].copy())


@dataclass
class ErrorModel:
    """The 9 navigation errors plus named augmented blocks (see the module docstring).

    Attributes
    ----------
    blocks : tuple of StateBlock
        The augmented blocks in state order, names unique, at most one lever-arm block; default
        none.
    accel_psd : ndarray, shape (3,)
        White-noise intensity of the accelerometers per axis [(m/s²)²·s]: velocity random walk
        squared.  One number stands for all three.
    gyro_psd : ndarray, shape (3,)
        White-noise intensity of the gyros per axis [(rad/s)²·s]: angle random walk squared.
    nav_sd : ndarray, shape (9,)
        Initial navigation standard deviations in state units (δL, δλ [rad], δh [m], δv [m/s],
        φ [rad]).

    Raises
    ------
    ValueError
        For duplicated block names, more than one lever-arm block, negative intensities or a
        ``nav_sd`` of another length.
    """

    blocks: tuple = ()
    accel_psd: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gyro_psd: np.ndarray = field(default_factory=lambda: np.zeros(3))
    nav_sd: np.ndarray = field(default_factory=lambda: np.zeros(9))

    def __post_init__(self):
        self.blocks = tuple(self.blocks)
        names = [b.name for b in self.blocks]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"duplicated block names {sorted(dup)}: each block needs a unique name")
        if sum(b.target == "lever_arm" for b in self.blocks) > 1:
            raise ValueError("at most one lever-arm block")
        self.accel_psd = np.broadcast_to(nonnegative_array(self.accel_psd, "accel_psd"), (3,)).copy()
        self.gyro_psd = np.broadcast_to(nonnegative_array(self.gyro_psd, "gyro_psd"), (3,)).copy()
        self.nav_sd = numeric(self.nav_sd, "nav_sd")
        if self.nav_sd.shape != (9,):
            raise ValueError("nav_sd needs 9 standard deviations (δL, δλ, δh, δv ENU, φ ENU)")
        _variances(self.nav_sd, "nav_sd")

    # -- layout
    @property
    def n(self) -> int:
        """Number of states, 9 plus the sizes of the blocks."""
        return 9 + sum(b.size for b in self.blocks)

    @property
    def slices(self) -> dict:
        """Named slices: ``position``, ``velocity``, ``attitude``, ``nav`` and one per block."""
        s = {"position": slice(0, 3), "velocity": slice(3, 6), "attitude": slice(6, 9), "nav": slice(0, 9)}
        k = 9
        for b in self.blocks:
            s[b.name] = slice(k, k + b.size)
            k += b.size
        return s

    @property
    def labels(self) -> list:
        """State labels: ``NAV_LABELS``, then ``"<block>.<label>"`` for each block component."""
        out = list(NAV_LABELS)
        for b in self.blocks:
            out += [f"{b.name}.{lab}" for lab in b.labels]
        return out

    def block(self, name) -> StateBlock:
        """The block named ``name``.

        Parameters
        ----------
        name : str
            Block name.

        Returns
        -------
        block : StateBlock
            The block.

        Raises
        ------
        KeyError
            When the model has no such block.
        """
        for b in self.blocks:
            if b.name == name:
                return b
        raise KeyError(f"no block {name!r}; blocks: {[b.name for b in self.blocks]}")

    def extend(self, *blocks) -> "ErrorModel":
        """A new model with ``blocks`` appended (the 15-state model extended to 36/45 states...).

        Parameters
        ----------
        *blocks : StateBlock
            Blocks to append, in order.

        Returns
        -------
        model : ErrorModel
            The extended model (``self`` is unchanged).
        """
        return replace(self, blocks=self.blocks + tuple(blocks))

    # -- constant parts and kernel encoding
    def kernel_encoding(self):
        """The model as the compiled filters take it.

        Returns
        -------
        fconst, qc : ndarray, shape (n, n)
            The constant part of F (the blocks' dynamics and the gravity output rows) and the
            process-noise PSD of the blocks.
        tg, kd, st, sz : ndarray of int64, shape (n_blocks,)
            Per block: target and kind codes, first state and size.
        """
        n = self.n
        fconst = np.zeros((n, n))
        qc = np.zeros((n, n))
        tg, kd, st, sz = [], [], [], []
        for b in self.blocks:
            s = self.slices[b.name]
            fconst[s, s] = b.dynamics
            qc[s, s] = b.noise_psd
            if b.target == "gravity":
                fconst[3:6, s] = -b.output
            tg.append(_TARGETS[b.target])
            kd.append(_KINDS[b.kind])
            st.append(s.start)
            sz.append(b.size)
        arr = lambda x: np.asarray(x, dtype=np.int64)
        return fconst, qc, arr(tg), arr(kd), arr(st), arr(sz)

    def P0(self) -> np.ndarray:
        """Diagonal initial covariance from ``nav_sd`` and the blocks' ``sd``.

        Returns
        -------
        P0 : ndarray, shape (n, n)
            diag(sd²) in state units squared.
        """
        sd = np.concatenate([self.nav_sd] + [b.sd for b in self.blocks])
        return np.diag(sd**2)

    # -- matrices
    def F(self, point: NavPoint) -> np.ndarray:
        """Continuous error-state matrix at ``point`` (chen2019 eqs. (3-14)-(3-16)).

        Parameters
        ----------
        point : NavPoint
            Where F is evaluated (latitude inside the polar limit :data:`~replication.nav.earth.POLAR_LIMIT_DEG`).

        Returns
        -------
        F : ndarray, shape (n, n)
            δẋ = F δx [1/s in state units].

        Raises
        ------
        ValueError
            For a latitude within the polar limit or an invalid field of ``point``.
        """
        earth.check_latitude(point.lat, polar_limit_deg=earth.POLAR_LIMIT_DEG)
        point.validate()
        fconst, _, tg, kd, st, sz = self.kernel_encoding()
        F = np.zeros((self.n, self.n))
        v = np.asarray(point.v_enu, float)
        K.build_F(float(point.lat), float(point.h), v[0], v[1], v[2], np.ascontiguousarray(point.C_bn, float),
                  np.asarray(point.f_b, float), np.asarray(point.w_ib_b, float), fconst, tg, kd, st, sz, F)
        return F

    def G_Qc(self, C_bn) -> np.ndarray:
        """Continuous process-noise intensity G Q Gᵀ for attitude C_b^n.

        Parameters
        ----------
        C_bn : array_like, shape (3, 3)
            Attitude DCM C_b^n that rotates the sensor noises into the n frame.

        Returns
        -------
        GQGt : ndarray, shape (n, n)
            The blocks' ``noise_psd`` plus C diag(accel_psd) Cᵀ on the velocity rows and
            C diag(gyro_psd) Cᵀ on the attitude rows [state unit²/s].
        """
        _, qc, *_ = self.kernel_encoding()
        q = qc.copy()
        C = rotation(C_bn, "C_bn")
        q[3:6, 3:6] += C @ np.diag(self.accel_psd) @ C.T
        q[6:9, 6:9] += C @ np.diag(self.gyro_psd) @ C.T
        return q

    def numerical_jacobian(self, point: NavPoint, *, steps=None) -> np.ndarray:
        """Central finite-difference Jacobian of the continuous mechanization.

        The mechanization is :func:`replication.nav.strapdown.navigation_rates`; the derivative is
        taken with respect to the error state.  Column j perturbs the state by ±ε_j:
        position/velocity additively, attitude by Ĉ = exp(-ε e_j×) C, sensor blocks through their
        coupling B(u) on f^b or ω_ib^b, gravity blocks through g^n.  Rows of the augmented blocks
        are their (constant) dynamics.

        Parameters
        ----------
        point : NavPoint
            Where the Jacobian is taken.
        steps : array_like, shape (n,), optional
            The steps ε_j in state units; default 1e-5 rad (δL, δλ), 100 m (δh), 1 m/s (δv),
            1e-4 rad (φ) and each block's ``fd_step``.

        Returns
        -------
        J : ndarray, shape (n, n)
            The Jacobian, comparable with :meth:`F` [1/s in state units].
        """

        point.validate()
        n = self.n
        eps = np.array([1e-5, 1e-5, 100.0, 1.0, 1.0, 1.0, 1e-4, 1e-4, 1e-4]
                       + [b.fd_step for b in self.blocks for _ in b.labels]) if steps is None else np.asarray(steps)
        C = np.asarray(point.C_bn, float)
        base = (float(point.lat), float(point.lon), float(point.h), np.asarray(point.v_enu, float), C)

        def err_rate(x_lat, x_lon, x_h, x_v, x_C, f_b, w_b, g_extra):
            r1 = navigation_rates(x_lat, x_lon, x_h, x_v, x_C, w_b, f_b, g_extra)
            r0 = navigation_rates(*base, point.w_ib_b, point.f_b)
            d = np.empty(9)
            d[0], d[1], d[2] = r1[0] - r0[0], r1[1] - r0[1], r1[2] - r0[2]
            d[3:6] = r1[3] - r0[3]
            Edot = r1[4] @ C.T + x_C @ r0[4].T
            d[6:9] = -0.5 * np.array([Edot[2, 1] - Edot[1, 2], Edot[0, 2] - Edot[2, 0], Edot[1, 0] - Edot[0, 1]])
            return d

        J = np.zeros((n, n))
        fconst, *_ = self.kernel_encoding()
        B = np.empty((3, 6))
        slices = self.slices
        for j in range(n):
            cols = []
            for sgn in (1.0, -1.0):
                e = sgn * eps[j]
                lat, lon, h, v, Cx = base[0], base[1], base[2], base[3].copy(), C
                f_b, w_b, gx = np.asarray(point.f_b, float).copy(), np.asarray(point.w_ib_b, float).copy(), np.zeros(3)
                if j < 3:
                    lat, lon, h = (lat + e, lon, h) if j == 0 else ((lat, lon + e, h) if j == 1 else (lat, lon, h + e))
                elif j < 6:
                    v[j - 3] += e
                elif j < 9:
                    ax = np.zeros(3)
                    ax[j - 6] = e
                    Cx = rotvec_to_dcm(-ax) @ C
                else:
                    for b in self.blocks:
                        s = slices[b.name]
                        if s.start <= j < s.stop:
                            x = np.zeros(b.size)
                            x[j - s.start] = e
                            if b.target in ("accel", "gyro"):
                                u = f_b if b.target == "accel" else w_b
                                K.coupling_matrix(_KINDS[b.kind], u, B)
                                du = B[:, :b.size] @ x
                                if b.target == "accel":
                                    f_b = f_b + du
                                else:
                                    w_b = w_b + du
                            elif b.target == "gravity":
                                gx = -b.output @ x
                cols.append(err_rate(lat, lon, h, v, Cx, f_b, w_b, gx))
            J[:9, j] = (cols[0] - cols[1]) / (2 * eps[j])
        J[9:, 9:] = fconst[9:, 9:]
        return J

    def propagate_linear(self, traj, x0, *, step: int = 10, order: int = 6):
        """Propagate δx along a trajectory with the linear model δẋ = F(t) δx (chen2019 eqs. (3-14)-(3-16)).

        δx_{j+1} = Φ_j δx_j, Φ_j = exp(F̄_j T_j) over intervals of ``step`` samples, T_j their
        duration and F̄_j the mean of F over the interval by Simpson's rule,
        F̄ = [F(t_0) + 4 F(t_½) + F(t_1)] / 6.  For an even ``step`` t_½ is a sample; for an odd
        one F(t_½) is the mean of the two samples around the midpoint (linear interpolation, exact
        for F linear in time), which for ``step=1`` reduces Simpson's rule to the trapezoid
        [F(t_0) + F(t_1)] / 2.  Φ_j by the truncated series of ``order`` terms.

        Parameters
        ----------
        traj : Trajectory
            A trajectory (``trajectory.generate``).
        x0 : array_like, shape (n,)
            The initial error state, in ``self.labels`` order and state units.
        step : int, optional
            Positive number of samples per interval, default 10 (an incomplete last interval is
            dropped).
        order : int, optional
            Number of terms of the series of Φ_j, default 6.

        Returns
        -------
        index : ndarray of int, shape (m,)
            Sample indices 0, step, 2 step, ... of the propagated states.
        dx : ndarray, shape (m, n)
            δx at those samples, state units.

        Raises
        ------
        TypeError
            For a ``traj`` that is not a Trajectory, or text, booleans or complex numbers in ``x0``.
        ValueError
            For an ``x0`` of another length or with a NaN or an infinity, a ``step`` that is not a
            positive integer, an ``order`` outside 1 … 64.
        """
        if not isinstance(traj, Trajectory):
            raise TypeError(f"traj must be a trajectory.Trajectory (trajectory.generate), got {type(traj).__name__}")
        x = finite_array(x0, "x0").copy()
        if x.shape != (self.n,):
            raise ValueError(f"x0 must have {self.n} components ({self.labels}), got shape {x.shape}")
        if isinstance(step, bool) or not isinstance(step, (int, float, np.integer, np.floating)) \
                or int(step) != step or step < 1:
            raise ValueError(f"step must be a positive integer number of samples per interval, got {step!r}")
        step = int(step)
        order = series_order(order, "order")
        fconst, _, tg, kd, st, sz = self.kernel_encoding()
        n = self.n
        idx = np.arange(0, traj.n + 1, step)
        out = np.empty((len(idx), n))
        out[0] = x
        F = np.zeros((n, n))
        Phi, Qd, w1, w2 = (np.empty((n, n)) for _ in range(4))
        Z = np.zeros((n, n))
        C_all = euler_to_dcm(traj.hpr[:, 0], traj.hpr[:, 1], traj.hpr[:, 2])

        def build(k):
            K.build_F(traj.lat[k], traj.h[k], traj.v_enu[k, 0], traj.v_enu[k, 1], traj.v_enu[k, 2],
                      np.ascontiguousarray(C_all[k]), traj.f_b[k], traj.w_ib_b[k], fconst, tg, kd, st, sz, F)
            return F.copy()

        for j in range(1, len(idx)):
            k0, k1 = idx[j - 1], idx[j]
            km = (k0 + k1) // 2
            # Simpson mean of F over the interval; an odd step interpolates F at the midpoint
            F_mid = build(km) if step % 2 == 0 else 0.5 * (build(km) + build(km + 1))
            Fa = np.zeros((n, n))
            Fa += build(k0)
            Fa += F_mid * 4.0
            Fa += build(k1)
            Fa /= 6.0
            K.discretize_series(Fa, Z, traj.t[k1] - traj.t[k0], order, Phi, Qd, w1, w2)
            x = Phi @ x
            out[j] = x
        return idx, finite_result(out, "the propagated error state overflows the float range: check the units of x0 "
                                       "(state units: rad, m, m/s, rad, then the blocks')")


# ----------------------------------------------------------------------------- block factories

def _variances(sd, name):
    """Non-negative standard deviations whose squares (the variances of P0) stay in the float range."""
    sd = nonnegative_array(sd, name)
    with np.errstate(over="ignore"):
        finite_result(sd * sd, f"{name} holds standard deviations up to {float(np.max(sd, initial=0)):.3g}: their "
                               "squares (the variances of P0) overflow the float range; check the unit")
    return sd


def _diag3(x, name):
    return np.diag(np.broadcast_to(nonnegative_array(x, name), (3,)))


def _sd(x, name, n=3):
    """``n`` standard deviations (one number standing for all): finite and non-negative."""
    return np.broadcast_to(nonnegative_array(x, name), (n,))


def accel_bias(sd=0.0, *, name="accel_bias", random_walk_psd=0.0):
    """Accelerometer random constant ∇_b (chen2019 eq. (2-5)); optional random walk.

    Parameters
    ----------
    sd : float or array_like, shape (3,), optional
        Initial standard deviation per axis [m/s²], default 0.
    name : str, optional
        Block name, default ``"accel_bias"``.
    random_walk_psd : float or array_like, shape (3,), optional
        Intensity of a random walk of the bias [(m/s²)²/s], default 0 (a random constant).

    Returns
    -------
    block : StateBlock
        Three ``identity`` states coupled into f^b.
    """
    return StateBlock(name, ("x", "y", "z"), "accel", "identity", noise_psd=_diag3(random_walk_psd, "random_walk_psd"),
                      sd=_sd(sd, "sd"), fd_step=1e-2)


def gyro_bias(sd=0.0, *, name="gyro_bias", random_walk_psd=0.0):
    """Gyro random constant drift ε_b (chen2019 eq. (2-5)); optional random walk.

    Parameters
    ----------
    sd : float or array_like, shape (3,), optional
        Initial standard deviation per axis [rad/s], default 0.
    name : str, optional
        Block name, default ``"gyro_bias"``.
    random_walk_psd : float or array_like, shape (3,), optional
        Intensity of a random walk of the drift [(rad/s)²/s], default 0 (a random constant).

    Returns
    -------
    block : StateBlock
        Three ``identity`` states coupled into ω_ib^b.
    """
    return StateBlock(name, ("x", "y", "z"), "gyro", "identity", noise_psd=_diag3(random_walk_psd, "random_walk_psd"),
                      sd=_sd(sd, "sd"), fd_step=1e-3)


def _markov(target, sigma, tau, name):
    tau = positive(tau, "tau", "correlation time {name} must be positive (seconds), got {value!r}")
    if tau < 1e-300:
        raise ValueError(f"correlation time tau = {tau!r} s is too small: the rate 1/tau overflows the float range")
    s = _sd(sigma, "sigma")
    return StateBlock(name, ("x", "y", "z"), target, "identity", dynamics=-np.eye(3) / tau,
                      noise_psd=np.diag(2 * s**2 / tau), sd=s, fd_step=1e-2 if target == "accel" else 1e-5)


def accel_markov(sigma, tau, *, name="accel_markov"):
    """First-order Gauss-Markov accelerometer bias ∇_m (eq. (2-5)); stationary σ, correlation τ.

    ẋ = -x/τ + w with intensity 2σ²/τ.

    Parameters
    ----------
    sigma : float or array_like, shape (3,)
        Stationary standard deviation σ per axis [m/s²] (also the initial one).
    tau : float
        Correlation time τ [s], positive.
    name : str, optional
        Block name, default ``"accel_markov"``.

    Returns
    -------
    block : StateBlock
        Three ``identity`` states coupled into f^b.
    """
    return _markov("accel", sigma, tau, name)


def gyro_markov(sigma, tau, *, name="gyro_markov"):
    """First-order Gauss-Markov gyro drift ε_m (eq. (2-5)); stationary σ, correlation τ.

    ẋ = -x/τ + w with intensity 2σ²/τ.

    Parameters
    ----------
    sigma : float or array_like, shape (3,)
        Stationary standard deviation σ per axis [rad/s] (also the initial one).
    tau : float
        Correlation time τ [s], positive.
    name : str, optional
        Block name, default ``"gyro_markov"``.

    Returns
    -------
    block : StateBlock
        Three ``identity`` states coupled into ω_ib^b.
    """
    return _markov("gyro", sigma, tau, name)


def accel_scale(sd=0.0, *, name="accel_scale"):
    """Accelerometer scale-factor errors δK_a (eq. (2-6)), dimensionless.

    Parameters
    ----------
    sd : float or array_like, shape (3,), optional
        Initial standard deviation per axis (dimensionless, 1 ppm = 1e-6), default 0.
    name : str, optional
        Block name, default ``"accel_scale"``.

    Returns
    -------
    block : StateBlock
        Three ``scale`` states coupled into f^b.
    """
    return StateBlock(name, ("x", "y", "z"), "accel", "scale", sd=_sd(sd, "sd"), fd_step=1e-3)


def gyro_scale(sd=0.0, *, name="gyro_scale"):
    """Gyro scale-factor errors δK_g (eq. (2-6)), dimensionless.

    Parameters
    ----------
    sd : float or array_like, shape (3,), optional
        Initial standard deviation per axis (dimensionless, 1 ppm = 1e-6), default 0.
    name : str, optional
        Block name, default ``"gyro_scale"``.

    Returns
    -------
    block : StateBlock
        Three ``scale`` states coupled into ω_ib^b.
    """
    return StateBlock(name, ("x", "y", "z"), "gyro", "scale", sd=_sd(sd, "sd"), fd_step=1e-3)


def _coupling_kind(coupling):
    choice(coupling, sorted(MISALIGNMENT_COUPLINGS), "coupling")
    return MISALIGNMENT_COUPLINGS[coupling]


def accel_misalignment(sd=0.0, *, name="accel_misalignment", coupling="axis-angles"):
    """Accelerometer non-orthogonality δA (eqs. (2-8), (2-9)).

    Parameters
    ----------
    sd : float or array_like, shape (6,), optional
        Initial standard deviations of [xy, yx, xz, zx, yz, zy] [rad], default 0.
    name : str, optional
        Block name, default ``"accel_misalignment"``.
    coupling : {"axis-angles", "cross-axis"}, optional
        How the six angles couple (:data:`MISALIGNMENT_COUPLINGS`), default ``"axis-angles"``.

    Returns
    -------
    block : StateBlock
        Six misalignment states coupled into f^b.
    """
    return StateBlock(name, _MIS_LABELS, "accel", _coupling_kind(coupling), sd=_sd(sd, "sd", 6), fd_step=1e-3)


def gyro_misalignment(sd=0.0, *, name="gyro_misalignment", coupling="axis-angles"):
    """Gyro non-orthogonality δG (eqs. (2-8), (2-9)).

    Parameters
    ----------
    sd : float or array_like, shape (6,), optional
        Initial standard deviations of [xy, yx, xz, zx, yz, zy] [rad], default 0.
    name : str, optional
        Block name, default ``"gyro_misalignment"``.
    coupling : {"axis-angles", "cross-axis"}, optional
        How the six angles couple (:data:`MISALIGNMENT_COUPLINGS`), default ``"axis-angles"``.

    Returns
    -------
    block : StateBlock
        Six misalignment states coupled into ω_ib^b.
    """
    return StateBlock(name, _MIS_LABELS, "gyro", _coupling_kind(coupling), sd=_sd(sd, "sd", 6), fd_step=1e-3)


def gravity_shaping(sigma, beta, *, name="gravity", dynamics=None, noise_psd=None, output=None, labels=None):
    """Gravity-disturbance states: chen2019 eq. (2-12) or a general shaping filter.

    Without ``dynamics``: δġ = -β δg + n per ENU axis with stationary σ (intensity 2βσ²).  With
    ``dynamics``, ``noise_psd`` and ``output``: a general shaping filter, e.g. the AR models of
    chen2019 ch. 3 in state-space form.

    Parameters
    ----------
    sigma : float or array_like, shape (3,) or (k,)
        Stationary (initial) standard deviation per state [m/s² for the eq. (2-12) form; the
        states' unit for a general filter].
    beta : float or array_like, shape (3,)
        Inverse correlation time β per ENU axis [1/s], positive; unused with ``dynamics``.
    name : str, optional
        Block name, default ``"gravity"``.
    dynamics : array_like, shape (k, k), optional
        Shaping-filter matrix A [1/s].
    noise_psd : array_like, shape (k, k), optional
        Intensity of its driving noise [state unit²/s], default zeros.
    output : array_like, shape (3, k), optional
        Map from the states to δg^n [m/s² per state unit], default the first three states.
    labels : sequence of str, optional
        Component labels of a general filter, default ``s0``, ``s1``, ...

    Returns
    -------
    block : StateBlock
        A ``gravity`` block (labels E, N, U for the eq. (2-12) form).

    Raises
    ------
    ValueError
        For a non-positive ``beta`` or inconsistent shapes.
    """
    if dynamics is None:
        s = _sd(sigma, "sigma")
        b = np.broadcast_to(finite_array(beta, "beta"), (3,))
        if np.any(b <= 0):
            raise ValueError("beta (inverse correlation time) must be positive")
        return StateBlock(name, ("E", "N", "U"), "gravity", dynamics=-np.diag(b), noise_psd=np.diag(2 * b * s**2),
                          sd=s, fd_step=1e-2)
    A = np.asarray(dynamics, float)
    k = A.shape[0]
    return StateBlock(name, tuple(labels or [f"s{i}" for i in range(k)]), "gravity", dynamics=A,
                      noise_psd=noise_psd, output=output, sd=_sd(sigma, "sigma", k), fd_step=1e-2)


def lever_arm(sd=0.0, *, name="lever_arm"):
    """Lever-arm (spatial synchronisation) error l of the GNSS antenna, chen2019 eq. (2-13).

    Parameters
    ----------
    sd : float or array_like, shape (3,), optional
        Initial standard deviation per body axis [m], default 0.
    name : str, optional
        Block name, default ``"lever_arm"``.

    Returns
    -------
    block : StateBlock
        Three constant states entering the GNSS measurement only.
    """
    return StateBlock(name, ("x", "y", "z"), "lever_arm", sd=_sd(sd, "sd"))


def model_15(*, position_sd=(10.0, 10.0, 10.0), velocity_sd=0.1, attitude_sd=(1e-4, 1e-4, 1e-3),
             accel_bias_sd=0.0, gyro_bias_sd=0.0, accel_psd=0.0, gyro_psd=0.0, lat=0.0, h=0.0) -> ErrorModel:
    """The classic 15-state model (chen2019 eqs. (3-14)-(3-16)).

    9 navigation errors, accelerometer bias ∇_b, gyro drift ε_b.  One number stands for the
    three components of any argument.

    Parameters
    ----------
    position_sd : float or array_like, shape (3,), optional
        Initial position standard deviation (E, N, U) [m], converted to (δL, δλ, δh) at
        (``lat``, ``h``); default 10 m.
    velocity_sd : float or array_like, shape (3,), optional
        Initial velocity standard deviation (E, N, U) [m/s], default 0.1.
    attitude_sd : float or array_like, shape (3,), optional
        Initial attitude standard deviation (E, N, U) [rad], default (1e-4, 1e-4, 1e-3).
    accel_bias_sd : float or array_like, shape (3,), optional
        Accelerometer bias standard deviation [m/s²], default 0.
    gyro_bias_sd : float or array_like, shape (3,), optional
        Gyro drift standard deviation [rad/s], default 0.
    accel_psd : float or array_like, shape (3,), optional
        Accelerometer white-noise intensity [(m/s²)²·s], default 0.
    gyro_psd : float or array_like, shape (3,), optional
        Gyro white-noise intensity [(rad/s)²·s], default 0.
    lat : float, optional
        Geodetic latitude [rad] of the metre-to-radian conversion, default 0.
    h : float, optional
        Ellipsoidal height [m] of the conversion, default 0.

    Returns
    -------
    model : ErrorModel
        Nine navigation states plus the blocks ``accel_bias`` and ``gyro_bias``.
    """
    ps = _sd(position_sd, "position_sd")
    earth.check_latitude(lat, polar_limit_deg=earth.POLAR_LIMIT_DEG, name="lat")
    earth.check_height(h, name="h")
    rm, rn = earth.radii(lat)
    nav_sd = np.concatenate([[ps[1] / (rm + h), ps[0] / ((rn + h) * np.cos(lat)), ps[2]],
                             _sd(velocity_sd, "velocity_sd"), _sd(attitude_sd, "attitude_sd")])
    return ErrorModel(blocks=(accel_bias(_sd(accel_bias_sd, "accel_bias_sd")), gyro_bias(_sd(gyro_bias_sd, "gyro_bias_sd"))),
                      accel_psd=_sd(accel_psd, "accel_psd"), gyro_psd=_sd(gyro_psd, "gyro_psd"), nav_sd=nav_sd)
