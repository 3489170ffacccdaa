"""chen2019's methods: the 45-state model, observability, error effects, the simulations,
turntable, calibration and gravity compensation.

``models`` and ``table_2_2`` (the error models and the printed F), ``observability``,
``maneuvers`` and ``observability_tables`` (Table 2-3), ``error_effects``, ``simulation`` and
``turntable`` (ch. 4 §2), ``imu_model``, ``calibration``, ``closed_forms``, ``temperature`` and
``static_tests`` (ch. 2 §2 and ch. 4 §1), ``gravity`` (ch. 3) and ``findings``.
"""
