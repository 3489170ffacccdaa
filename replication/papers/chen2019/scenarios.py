"""The motions chen2019 prints: the survey flight of Table 4-42 (initial state of Table 4-41's text)
and the three-axis turntable sequences of §4.1.3, built from the segments of
:mod:`replication.nav.trajectory`.
"""

from __future__ import annotations

import numpy as np

from replication.nav.trajectory import Dwell, Straight, STurn, UTurn, move
from replication.nav.units import DEG


def chen2019_flight(*, s_swing: float = np.pi, s_cycles: int = 2):
    """Segments of chen2019 Table 4-42 (the 5100-s survey flight) and its initial state.

    Table 4-42: 0-100 s straight; 100-1300 s S-maneuver; 1300-2300 s straight; 2300-2700 s
    clockwise 180° U-turn; 2700-3700 s straight; 3700-4100 s counter-clockwise 180° U-turn;
    4100-5100 s straight; constant speed and height, bank in the turns.  Initial state of
    Table 4-41's text: 47°N, 115°E, 6000 m, heading 45° (north-east), 100 m/s.
    The S-maneuver's amplitude is not printed: ``s_swing`` (default 180°) and ``s_cycles``
    (default 2) are this package's choice.

    Parameters
    ----------
    s_swing : float, optional
        Heading excursion of the S-maneuver [rad], default π.
    s_cycles : int, optional
        Its number of cycles, default 2.

    Returns
    -------
    segments : list of replication.nav.trajectory.Segment
        The flight.
    initial : dict
        The keyword arguments of :func:`~replication.nav.trajectory.generate` (``lat0``, ``lon0`` [rad], ``h0`` [m],
        ``heading`` [rad], ``speed`` [m/s]).
    """
    segs = [Straight(100.0), STurn(1200.0, swing=s_swing, cycles=s_cycles), Straight(1000.0),
            UTurn(400.0, clockwise=True), Straight(1000.0), UTurn(400.0, clockwise=False), Straight(1000.0)]
    init = dict(lat0=47 * DEG, lon0=115 * DEG, h0=6000.0, heading=45 * DEG, speed=100.0)
    return segs, init


def turntable_chen2019(experiment: int = 2, *, dwell: float = 300.0, repeats: int = 3,
                       outer_rate: float = 9 * DEG, middle_rate: float = 1 * DEG, ramp: float = 1.0):
    """Three-axis turntable sequences of chen2019 §4.1.3 (ch. 4, "SINS/GNSS 姿态仿真测试").

    experiment 1: no roll — outer axis to -180° and back to 0° at 9°/s, dwelling ``dwell`` s;
    experiment 2: coordinated-turn simulation — outer to -90° then -180° (9°/s), dwell, outer to
    -90° with middle (roll) to 10° (1°/s) simultaneously, then both back to 0°, dwell;
    experiment 3: as 2 with the IMU initially north-west-up ([90, 0, 0] in the report's
    counter-clockwise yaw, i.e. heading -90°).  Steps repeated ``repeats`` times.
    The outer angle α maps to heading ψ = -α, the middle (roll) axis to roll γ.  Each move
    accelerates and decelerates smoothly over ``ramp`` seconds (:func:`~replication.nav.trajectory.move`).

    Parameters
    ----------
    experiment : {1, 2, 3}, optional
        Which experiment, default 2.
    dwell : float, optional
        Rest between moves [s], default 300.
    repeats : int, optional
        Repetitions of the steps, default 3.
    outer_rate : float, optional
        Outer-axis (heading) rate [rad/s], default 9°/s.
    middle_rate : float, optional
        Middle-axis (roll) rate [rad/s], default 1°/s.
    ramp : float, optional
        Ramp of each move [s], default 1.

    Returns
    -------
    segments : list of replication.nav.trajectory.Segment
        An initial dwell, then the moves and dwells.
    initial_heading : float
        Initial heading [rad]: 0, or -π/2 for experiment 3.

    Raises
    ------
    ValueError
        For another experiment number.
    """
    if experiment not in (1, 2, 3):
        raise ValueError("experiment must be 1, 2 or 3 (chen2019 §4.1.3)")
    segs = [Dwell(dwell)]
    a, m = outer_rate, middle_rate
    for _ in range(repeats):
        if experiment == 1:
            segs += [move((np.pi, 0, 0), a, ramp), Dwell(dwell), move((-np.pi, 0, 0), a, ramp), Dwell(dwell)]
        else:
            segs += [move((np.pi / 2, 0, 0), a, ramp), move((np.pi / 2, 0, 0), a, ramp), Dwell(dwell),
                     move((-np.pi / 2, 0, 10 * DEG), (a, 0, m), ramp), move((-np.pi / 2, 0, -10 * DEG), (a, 0, m), ramp),
                     Dwell(dwell)]
    return segs, (0.0 if experiment in (1, 2) else -90 * DEG)
