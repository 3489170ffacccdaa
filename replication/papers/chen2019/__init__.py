"""chen2019's methods: the 45-state model, observability, error effects, the simulations,
turntable, calibration and gravity compensation.
"""
