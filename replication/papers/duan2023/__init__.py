"""duan2023's SINS/ADS error-correction method, one concept per module.

``geometry`` (the corrections of one interval, eqs. (2)-(22)), ``derivation`` (their sympy
re-derivation and the SINS error matrix of eq. (1)), ``printed`` (the printed elements against the
derivation, eq. (21) integrated), ``flight`` (the simulated flight, its parameters and sensors),
``method`` (the error-correction method in flight, and the pure SINS), ``literature`` (the SINS/ADS
Kalman filter of refs. [15-17]), ``experiments`` (controlled experiments on one correction),
``montecarlo`` (the three systems compared, Table 1), ``claims`` (the numbers behind the stated
claims), ``sweeps`` (sweeps, diagnostics and attitude readings) and ``findings`` (the rows the
chapter hands to the registry).
"""
