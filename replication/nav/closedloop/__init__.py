"""The closed-loop (feedback) INS/GNSS error-state Kalman filter: one compiled loop for every
chapter, batched over Monte-Carlo runs.

One IMU step of every run: the accumulated sensor-error estimates are removed from the
increments (chen2019 eq. (2-10)) and the strapdown of ``replication.nav._kernels.sd_step``
(chen2019 eq. (3-2)) advances the run.  One GNSS epoch: the error-state F of
``replication.nav._kernels.build_F_core`` plus the sensor-block couplings C_b^n B(u) — both
averaged over the interval's IMU steps (F is affine in them, so this is the interval mean of F)
— gives (Φ, Q_d) by the Van Loan series; P⁻ = Φ P Φᵀ + Q_d; the measurement rows come from the
*measurements* in use (:mod:`replication.nav.measurements`): each is a value supplying two
compiled kernels of one signature, its rows of H with their variances and its residuals, which
the compiled loop calls in turn through a tuple of first-class functions and never names — GNSS
antenna position and velocity with the lever arm (chen2019 eq. (2-13)), the specific force of
chen2019 eq. (3-18), the air-data height and airspeed, a zero-velocity update, a barometric
height, or an aid of the caller's own module; the update is the
Joseph form one (independent) measurement at a time; then the navigation errors are fed back and
the sensor-error estimates accumulated.  Optional: a vertical channel held or damped
(:mod:`replication.nav.strapdown`), discrete AR transitions of a gravity block at chosen epochs, the
recording of what the fixed-interval smoother needs (Φ, rows, gains and innovations for the
modified Bryson-Frazier form :func:`mbf_chunk`; P⁺, P⁻, Φ, x̂ for the Rauch-Tung-Striebel form
:func:`rts_chunk`), NEES against a truth.

**Batches.** The covariance, the gains and the measurement matrix of a batch come from its
first run (the *lead*); every run applies them to its own innovations, so run 0 is an exact
extended Kalman filter and the other runs are the same filter linearized along run 0 (their
navigation errors differ by metres and milliradians: the difference is second order).  A batch
of one is the single-run filter.  The lead's pass records per epoch what the other runs need
(H rows, gains, innovation variances, the Φ rows of the sensor-error dynamics), so the runs can
follow on other threads, chunk by chunk, while the lead goes on: the result does not depend on
the number of threads.

The one public entry point is :func:`replication.nav.filter.run_filter` (used by
:func:`replication.nav.kalman.closed_loop`, :func:`replication.nav.kalman.monte_carlo`,
:func:`replication.papers.chen2019.simulation.run_batch`,
:func:`replication.papers.chen2019.gravity.augmented_filter` and
``replication.papers.duan2023.airdata.literature_filter``); here :func:`run` is the engine's
driver (chunks, threads, records, smoother), :func:`build_spec` bundles the configuration of an
:class:`replication.nav.errors.ErrorModel` and the measurements, :func:`chunk_inputs` and
:func:`array_inputs` build its inputs.

**Modules.** One concept each: ``options`` (:class:`Options`, :class:`Smoother`), ``bundles`` (the
numba-compatible bundles :class:`Spec`, :class:`ChunkInputs`, :class:`BatchState`,
:class:`LeadState`, :class:`Gains`, :class:`ChunkOut`), ``spec`` (the configuration and the runs'
initial state), ``inputs`` (a chunk's inputs), ``timeupdate`` (the compiled IMU steps and time
update), ``update`` (the compiled measurement pass and sequential update), ``forward`` (the
compiled chunk, :func:`filter_chunk`), ``smoother`` (:func:`mbf_chunk`, :func:`rts_chunk`),
``records`` (:class:`FilterResult`, :func:`innovation_covariance`) and ``driver`` (:func:`run`).  Every name is importable from
``replication.nav.closedloop``.
"""

from __future__ import annotations

from replication.nav.closedloop import spec as _spec
from replication.nav.closedloop.bundles import BatchState, ChunkInputs, ChunkOut, Gains, LeadState, Spec
from replication.nav.closedloop.driver import run
from replication.nav.closedloop.forward import filter_chunk
from replication.nav.closedloop.inputs import array_inputs, chunk_inputs, counting_inputs
from replication.nav.closedloop.options import Options, Smoother, resolve_options
from replication.nav.closedloop.records import FilterResult, innovation_covariance
from replication.nav.closedloop.smoother import mbf_chunk, rts_chunk
from replication.nav.closedloop.spec import GnssRows, build_spec, initial_batch_state

#: The most measurements of one filter (defined in ``spec``): the kernel tuples of :class:`Spec` are
#: padded to this length with kernels that write no row, so one compiled loop serves every set of aids.
MAX_MEASUREMENTS = _spec.MAX_MEASUREMENTS

# the public entry point is replication.nav.filter.run_filter; the engine's bundles and builders stay here
__all__ = ["Options", "Smoother", "GnssRows", "FilterResult", "resolve_options", "MAX_MEASUREMENTS", "Spec",
           "build_spec", "ChunkInputs", "BatchState", "LeadState", "Gains", "ChunkOut", "initial_batch_state", "run",
           "filter_chunk", "rts_chunk", "mbf_chunk", "chunk_inputs", "array_inputs", "counting_inputs",
           "innovation_covariance"]
