"""The ship motion of fang2020 §3: the rocking of eq. (28) on a course at 10 m/s, built from
:class:`replication.nav.trajectory.ShipRocking`.
"""

from __future__ import annotations

import numpy as np

from replication.nav._validate import positive
from replication.nav.trajectory import ShipRocking
from replication.nav.units import DEG


def fang2020_ship(duration: float, rng=None, *, northward: bool = False):
    """fang2020 §3 ship motion: eq. (28) rocking (3°, 5°, 4°; 7, 9, 12 s; random phases).

    10 m/s east along the parallel (heading 90°) or, with ``northward``, north along the meridian
    (heading 0°).

    Parameters
    ----------
    duration : float
        Length [s].
    rng : numpy.random.Generator or int or None, optional
        Draws the three phases (uniform on [0, 2π)).
    northward : bool, optional
        Sail north instead of east, default False.

    Returns
    -------
    segments : list of replication.nav.trajectory.ShipRocking
        One rocking segment.
    """
    duration = positive(duration, "duration", "fang2020_ship: duration must be a positive number of seconds, "
                                              "got {value!r}")
    rng = np.random.default_rng(rng)
    ph = tuple(rng.uniform(0, 2 * np.pi, 3))
    head = 0.0 if northward else 90 * DEG
    return [ShipRocking(duration, phases=ph, heading0=head, course=head)]
