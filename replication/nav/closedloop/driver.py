"""The driver of the closed-loop filter (:func:`run`): the chunks, the lead's pass and the runs that
follow it on other threads, the checkpoints and replays of the smoother.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Callable

import numpy as np

from replication.nav._validate import covariance, integer, numeric
from replication.nav.closedloop.bundles import BatchState, ChunkInputs, ChunkOut, Gains, LeadState, Spec
from replication.nav.closedloop.forward import filter_chunk
from replication.nav.closedloop.options import Options, resolve_options
from replication.nav.closedloop.records import FilterResult, _collect, _new_records, _record_positions
from replication.nav.closedloop.smoother import _smooth
from replication.nav.closedloop.spec import _split, _with_phat


def _empty_gains(E_, n, n_dyn, n_aug, with_nees, m_max):
    E_n = E_ if with_nees else 0
    return Gains(np.zeros(E_, np.int64), np.zeros((E_, m_max, n)), np.zeros((E_, m_max, n)),
                 np.ones((E_, m_max)), np.zeros((E_, max(n_dyn, 0), n_aug)), np.empty((E_n, n)),
                 np.empty((E_n, n, n)))


def _run_arguments(spec: Spec, P0, ep_samples, n_steps: int):
    """The checked epoch samples and initial covariance of :func:`run` (``ValueError`` otherwise)."""
    if not isinstance(spec, Spec):
        raise TypeError(f"spec must be a closedloop.Spec (closedloop.build_spec), got {type(spec).__name__}")
    n_steps = integer(n_steps, "n_steps")
    e = numeric(ep_samples, "ep_samples")
    if e.ndim != 1 or len(e) < 1 or not np.all(np.isfinite(e)) or np.any(e != np.round(e)):
        raise ValueError(f"ep_samples must be a non-empty 1-D array of whole sample indices, got {e!r:.60}")
    ep = np.asarray(ep_samples, np.int64)
    n = spec.fconst.shape[0]
    if np.any(np.diff(ep) <= 0) or ep[0] < 1 or ep[-1] > n_steps:
        raise ValueError(f"ep_samples must be strictly increasing sample indices in 1..{n_steps}")
    P0 = np.array(numeric(P0, "P0"), dtype=float)
    if P0.shape != (n, n):
        raise ValueError(f"P0 must be {n}×{n}")
    covariance(P0, "P0")
    return ep, P0


def _follower_groups(R: int, workers: int) -> list:
    """Slices of the runs 1..R−1 for at most ``workers`` follower threads (none for a single run)."""
    n_groups = min(int(workers), R - 1) if R > 1 else 0
    return [slice(1 + g * (R - 1) // n_groups, 1 + (g + 1) * (R - 1) // n_groups) for g in range(n_groups)]


def _out_view(o: ChunkOut, sl) -> ChunkOut:
    """The runs ``sl`` of a chunk's outputs (per-run fields sliced, shared fields as they are)."""
    per_run = {"st", "q", "phat", "nis", "innov", "nees", "nav_st", "nav_q", "rec_x"}
    return ChunkOut(*(v[sl] if k in per_run else v for k, v in zip(ChunkOut._fields, o)))


def _inputs_view(x: ChunkInputs, sl) -> ChunkInputs:
    """The runs ``sl`` of a chunk's inputs (per-run fields sliced, shared fields as they are)."""
    per_run = {"dth", "dvv", "obs", "truth_p"}
    return ChunkInputs(*(v[sl] if k in per_run else v for k, v in zip(ChunkInputs._fields, x)))


class _ChunkPlan:
    """The chunks of one call of :func:`run` and the filter's work on one chunk (lead, followers, replay)."""

    def __init__(self, spec: Spec, ep, n_steps: int, rec_pos, R: int, inputs, lead_inputs, opt: Options):
        n_ep = len(ep)
        self.spec, self.ep, self.n_steps, self.rec_pos, self.R = spec, ep, n_steps, rec_pos, R
        self.groups = _follower_groups(R, opt.workers)
        self.inputs, self.lead_inputs = inputs, lead_inputs
        self.store_nav, self.store_P = opt.store_nav, opt.store_P
        self.rts = opt.smoother is not None and opt.smoother.form == "rts"
        chunk_epochs = opt.chunk_epochs
        self.chunks = [(j0, min(j0 + int(chunk_epochs), n_ep)) for j0 in range(0, n_ep, int(chunk_epochs))]
        self.n = spec.fconst.shape[0]
        self.n_aug = self.n - 9
        self.n_dyn = len(spec.dyn_rows)
        # the lead's replay for the smoother: neither the covariance without measurements nor the NEES
        self.spec_replay = spec._replace(use_pbar=False, nees=False)

    def bounds(self, ci):
        """Epochs j0..j1−1 and IMU steps k0..k1−1 of chunk ``ci``."""
        j0, j1 = self.chunks[ci]
        k0 = 0 if ci == 0 else int(self.ep[j0 - 1])
        k1 = self.n_steps if ci == len(self.chunks) - 1 else int(self.ep[j1 - 1])
        return j0, j1, k0, k1

    def chunk_out(self, j0, j1, k0, k1, record, R=None, store_nav=None) -> ChunkOut:
        """Output arrays of one chunk for ``R`` runs (all by default); ``record`` for the smoother's replay."""
        R = self.R if R is None else R
        store_nav = self.store_nav if store_nav is None else store_nav
        n, rec_pos, spec, rts = self.n, self.rec_pos, self.spec, self.rts
        E_ = j1 - j0
        flag = rec_pos[j0:j1] - (rec_pos[j0:j1][rec_pos[j0:j1] >= 0].min() if np.any(rec_pos[j0:j1] >= 0) else 0)
        flag = np.where(rec_pos[j0:j1] >= 0, flag, -1).astype(np.int64)
        n_f = int(np.sum(flag >= 0))
        nav = (k1 - k0 + 1) if store_nav else 0
        e3 = np.empty((0, n, n))
        # the smoother's replay (``record``) keeps Φ per epoch and P⁺ at the recorded epochs; the RTS
        # form also P⁺, P⁻ and the estimates x̂ per epoch
        return ChunkOut(np.empty((R, E_, 6)), np.empty((R, E_, 4)), np.empty((R, E_, self.n_aug)), np.empty((R, E_)),
                        np.zeros((R, E_, spec.m_max)), np.full((R, E_), np.nan) if spec.nees else np.empty((R, 0)),
                        np.empty((R, nav, 6)), np.empty((R, nav, 4)), np.empty((E_, n)), flag,
                        np.empty((n_f, n, n)) if self.store_P or record else e3,
                        np.empty((n_f, n, n)) if spec.use_pbar and self.store_P else e3,
                        np.empty((E_, n, n)) if record and rts else e3, np.empty((E_, n, n)) if record and rts else e3,
                        np.empty((E_, n, n)) if record else e3,
                        np.empty((R, E_, n)) if record and rts else np.empty((R, 0, n)))

    def prepare(self, ci, record):
        """Epochs, inputs, output arrays and empty gains of chunk ``ci`` for every run."""
        j0, j1, k0, k1 = self.bounds(ci)
        return (j0, j1, self.inputs(ci, k0, k1, self.ep[j0:j1]), self.chunk_out(j0, j1, k0, k1, record),
                _empty_gains(j1 - j0, self.n, self.n_dyn, self.n_aug, self.spec.nees, self.spec.m_max))

    def lead_pass(self, st_, lead_, x, g, o):
        """Run 0 over one chunk, leaving the gains ``g`` for the followers."""
        filter_chunk(self.spec, _inputs_view(x, slice(0, 1)), _split(st_, slice(0, 1)), lead_, g,
                     _out_view(o, slice(0, 1)), True)

    def start_followers(self, st_, lead_, x, g, o):
        """Threads running the followers of one chunk (their state views are taken now)."""
        threads = [threading.Thread(target=filter_chunk, args=(self.spec, _inputs_view(x, sl), _split(st_, sl), lead_,
                                                               g, _out_view(o, sl), False)) for sl in self.groups]
        for t in threads:
            t.start()
        st_.first[0] = 0
        return threads

    def forward(self, ci, st_, lead_, record):
        """Lead over the chunk, then its followers, joined before return."""
        j0, j1, x, o, g = self.prepare(ci, record)
        self.lead_pass(st_, lead_, x, g, o)
        for t in self.start_followers(st_, lead_, x, g, o):
            t.join()
        return j0, j1, o, g

    def replay_lead(self, ci, st0, lead_):
        """The lead alone over chunk ``ci`` from its checkpoint, recording for the smoother."""
        j0, j1, k0, k1 = self.bounds(ci)
        x = (self.lead_inputs(ci, k0, k1, self.ep[j0:j1]) if self.lead_inputs is not None
             else _inputs_view(self.inputs(ci, k0, k1, self.ep[j0:j1]), slice(0, 1)))
        o = self.chunk_out(j0, j1, k0, k1, True, R=1, store_nav=False)
        g = _empty_gains(j1 - j0, self.n, self.n_dyn, self.n_aug, False, self.spec.m_max)
        filter_chunk(self.spec_replay, x, st0, lead_, g, o, True)
        return j0, j1, o, g

    def replay(self, checkpoints, ci):
        """Chunk ``ci`` replayed from its checkpoint (released) for the smoother."""
        st_c, lead_c = checkpoints[ci]
        checkpoints[ci] = None
        return self.forward(ci, st_c, lead_c, True) if self.rts else self.replay_lead(ci, st_c, lead_c)


def _checkpoint(plan: _ChunkPlan, state: BatchState, row0):
    """What the smoother's replay of a chunk starts from: every run (RTS form) or the lead alone (MBF form)."""
    if not plan.rts:
        return row0
    ck = BatchState(*(v.copy() for v in state))
    for v, v0 in zip(ck, row0[0]):
        v[:1] = v0
    return ck, row0[1]


def _forward_pass(plan: _ChunkPlan, state: BatchState, lead: LeadState, res: FilterResult, smoother: bool):
    """The filter over every chunk, pipelined, into ``res``; returns the smoother's checkpoints and innovations.

    The lead runs chunk c while the followers finish chunk c − 1 and the inputs of chunk c + 1 are
    prepared (``inputs`` is called in chunk order, from one thread)."""
    chunks, rts = plan.chunks, plan.rts
    checkpoints = []
    innov = [None] * len(chunks)
    pending = None
    prep = ThreadPoolExecutor(max_workers=1)
    try:
        nxt_prep = prep.submit(plan.prepare, 0, False)
        for ci in range(len(chunks) + 1):
            if ci < len(chunks):
                j0, j1, x, o, g = nxt_prep.result()
                if ci + 1 < len(chunks):
                    nxt_prep = prep.submit(plan.prepare, ci + 1, False)
                row0 = (BatchState(*(v[:1].copy() for v in state)), LeadState(*(v.copy() for v in lead)))
                plan.lead_pass(state, lead, x, g, o)
            if pending is not None:
                for t in pending[0]:
                    t.join()
                _collect(res, pending[1], pending[2], pending[3], plan.rec_pos, plan.spec, pending[4], pending[5])
                if smoother and not rts:
                    # every run's innovations, for the smoother (the rows in use)
                    innov[ci - 1] = np.ascontiguousarray(pending[3].innov[:, :, :int(pending[5].m.max())])
                pending = None
            if ci == len(chunks):
                break
            if smoother:
                checkpoints.append(_checkpoint(plan, state, row0))
            pending = (plan.start_followers(state, lead, x, g, o), j0, j1, o,
                       plan.bounds(ci)[2] if plan.store_nav else None, g)
    finally:
        prep.shutdown()
    return checkpoints, innov


def run(spec: Spec, state: BatchState, P0, ep_samples, n_steps: int,
        inputs: Callable[[int, int, int, np.ndarray], ChunkInputs], *,
        lead_inputs: Callable[[int, int, int, np.ndarray], ChunkInputs] | None = None,
        options: Options | None = None) -> FilterResult:
    """Run the closed-loop filter of ``spec`` over ``n_steps`` IMU steps for the runs of ``state``.

    Parameters
    ----------
    spec : Spec
        From :func:`build_spec`.
    state : BatchState
        From :func:`initial_batch_state` (modified in place).
    P0 : (n, n) array_like
        Initial covariance.
    ep_samples : (E,) array_like of int
        IMU sample index of each GNSS epoch (1..n_steps, strictly increasing).
    n_steps : int
        Number of IMU steps.
    inputs : callable
        ``inputs(chunk, k0, k1, ep_samples_of_chunk)`` → :class:`ChunkInputs` for steps k0..k1-1
        (deterministic: the smoother replays chunks).  The forward pass calls it in chunk order
        from one helper thread (the next chunk's inputs are prepared while the lead runs).
    lead_inputs : callable, optional
        The same for run 0 alone (arrays of one run), for the smoother's replay of the lead (two
        chunks at once, from two threads); by default run 0's slice of ``inputs``.
    options : Options, optional
        Records (``record_every``, ``store_nav``, ``store_P``), chunking (``chunk_epochs``), the
        smoother pass (``smoother``: a :class:`Smoother`, replaying the forward pass chunk by
        chunk), threads (``workers``) and the innovation covariances (``innovations``); unset fields
        take run's defaults (every epoch recorded, 2000 epochs per chunk, no smoother, no IMU-rate
        solution, P kept, 2 threads, no innovation covariances).

    Returns
    -------
    Records
    """
    opt = resolve_options(options)
    ep, P0 = _run_arguments(spec, P0, ep_samples, n_steps)
    if not isinstance(state, BatchState):
        raise TypeError(f"state must be a closedloop.BatchState (closedloop.initial_batch_state), got "
                        f"{type(state).__name__}")
    if not callable(inputs) or (lead_inputs is not None and not callable(lead_inputs)):
        raise TypeError("inputs (and lead_inputs) must be callables (chunk, k0, k1, epochs) -> ChunkInputs")
    n = spec.fconst.shape[0]
    state = _with_phat(state, n - 9)
    R = state.st.shape[0]
    rec_ep, rec_pos = _record_positions(len(ep), opt.record_every)
    res = _new_records(spec, rec_ep, R, n, len(ep), n_steps, opt.store_P, opt.store_nav, opt.innovations)
    lead = LeadState(P0.copy(), P0.copy(), np.zeros(3), np.zeros((6, n)))
    plan = _ChunkPlan(spec, ep, n_steps, rec_pos, R, inputs, lead_inputs, opt)
    smoother = opt.smoother is not None
    checkpoints, innov = _forward_pass(plan, state, lead, res, smoother)
    if smoother:
        _smooth(res, plan.chunks, lambda ci: plan.replay(checkpoints, ci), innov, rec_pos, R, n, len(rec_ep),
                opt.smoother.covariance, plan.rts)
    return res

