"""an2021's transfer functions from gravity disturbance to horizontal attitude.
"""
