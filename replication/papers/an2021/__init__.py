"""an2021's transfer functions from gravity disturbance to horizontal attitude.

``transfer`` (the free SINS's error model, transfer functions and zero/pole maps), ``symbolic``
(their closed forms, derived, and the printed coefficients checked), ``integrated`` (the
position-aided mode) and ``frequency`` (frequency-response features).
"""
