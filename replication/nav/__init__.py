"""The navigation toolkit: Earth model, units, rotations, trajectories, sensor models, strapdown,
error-state models, the Kalman filter and the closed-loop filter, time-series statistics.
Reusable beyond the papers; imports nothing else of the package.
"""
