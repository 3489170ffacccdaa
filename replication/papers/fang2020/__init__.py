"""fang2020's polar grid INS and its two-point calibration, one concept per module.

``frames`` (grid, OEPQ, computer and platform frames), ``damping`` (the external horizontal
damping network), ``error_equations`` (the P and ψ equations), ``two_point`` (the two-point
comprehensive calibration), ``polar`` (the simulation of §3) and ``sensitivity`` (its sensitivity
and readings ledger).
"""
