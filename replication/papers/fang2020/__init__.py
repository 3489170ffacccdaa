"""fang2020's polar grid INS and its two-point calibration.
"""
