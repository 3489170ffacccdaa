"""Independent second computations of the headline verdicts.

Each module here recomputes one simulated artifact's headline result by a route that shares no
code path with the chapter's main computation (a linear error-model propagation against the
nonlinear simulation, a closed form against a Monte Carlo, another observability criterion),
written from the paper alone.  The chapter shows both results side by side; the tests assert
their agreement within a tolerance stated from the physics.  Only numpy/scipy and the paper's own
equations are used, so that an error in the chapter's code cannot repeat itself here.
"""
