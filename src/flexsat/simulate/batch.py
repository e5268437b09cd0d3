"""A whole slew in one compiled call, and many slews in one compiled call (threads).

:func:`fly` runs a prepared slew (:func:`flexsat.simulate.closedloop.prepare_slew`)
chunk by chunk exactly as the progress-reporting driver does (the same chunk
boundaries, the same arithmetic), so a slew flown alone, in a batch or with a
progress bar gives the same records bit for bit. :func:`fly_batch` runs a batch of
prepared slews of one structure (same law, stage chains and appendage groups: one
numba type) across ``numba.prange`` threads, each writing only its own arrays.
Both release the GIL.

:func:`fly_prepared` types each slew by its structure (:func:`item_type`: the numba
type of a :class:`BatchItem`, computed once per structure) and appends it to the
batch's typed list through the compiled overload for that type, so that a case costs
no dispatcher typing of its hundred-odd arrays and kernels (docs/performance.md,
"Campaign cases").
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import config, njit, prange, set_num_threads, typeof, types

from flexsat.compiled.typed_call import typed_append, typed_list
from flexsat.simulate.loops import LoopClock, LoopRecords, rk4_closed_loop
from flexsat.simulate.run_setup import chunk_steps

__all__ = [
    "BatchItem",
    "SlewTiming",
    "batch_item",
    "fly",
    "fly_batch",
    "fly_entry",
    "fly_prepared",
    "fly_whole",
    "item_type",
    "slew_timing",
]


class SlewTiming(NamedTuple):
    """A slew's clock: RK4 step, length and the periods in steps.

    Attributes
    ----------
    dt : float
        RK4 step [s].
    n_steps : int
        Steps of the whole run [-].
    control_every : int
        Plant steps per control period [-].
    record_every : int
        Plant steps per record [-].
    chunk : int
        Steps per compiled chunk (:func:`flexsat.simulate.run_setup.chunk_steps`) [-].
    continuous : bool
        An actuation stage integrates states in the RK4 steps [-].
    """

    dt: float  # RK4 step [s]
    n_steps: int  # steps of the whole run
    control_every: int  # plant steps per control period
    record_every: int  # plant steps per record
    chunk: int  # steps per compiled chunk (flexsat.simulate.run_setup.chunk_steps)
    continuous: bool  # an actuation stage integrates states in the RK4 steps


class BatchItem(NamedTuple):
    """One prepared slew as :func:`fly_batch` takes it (arrays shared, not copied).

    Attributes
    ----------
    x : ndarray, shape (x_size,)
        Plant state [m, rad, m/s, rad/s, J], advanced in place.
    timing : SlewTiming
        The slew's clock [-].
    stages : tuple
        The compiled law and stages (``LoopStages``) [-].
    data : tuple
        The loop's arrays (``LoopData``) [-].
    rec_t : ndarray, shape (m,)
        Record times [s].
    rec_x : ndarray, shape (m, x_size)
        Recorded plant states [m, rad, m/s, rad/s, J].
    rec_ctrl : ndarray, shape (m, record_size)
        Recorded control rows [SI units of each channel].
    rec_frame : ndarray, shape (m, 9)
        Recorded attitude references R_NF [-].
    rec_Q : ndarray, shape (m, n_dof)
        Recorded joint-actuator forces, hub columns zero [N, N m per coordinate].
    rec_solved : ndarray, shape (m, 2, n_dof)
        Recorded q_ddot and constraint forces where the loop has them
        (``LoopRecords.solved``) [m/s^2, rad/s^2; N, N m per coordinate].
    plant : tuple
        The plant's named structure (``Plant.packed``) [-].
    frame : ndarray, shape (9,)
        Attitude reference R_NF of ``x`` [-], updated in place.
    """

    x: np.ndarray
    timing: SlewTiming
    stages: tuple
    data: tuple
    rec_t: np.ndarray
    rec_x: np.ndarray
    rec_ctrl: np.ndarray
    rec_frame: np.ndarray
    rec_Q: np.ndarray
    rec_solved: np.ndarray
    plant: tuple
    frame: np.ndarray


def slew_timing(run) -> SlewTiming:
    """The :class:`SlewTiming` of a prepared slew.

    Parameters
    ----------
    run : PreparedSlew
        The slew (:func:`flexsat.simulate.closedloop.prepare_slew`).

    Returns
    -------
    SlewTiming
    """
    s = run.scenario
    return SlewTiming(s.dt_s, s.n_steps, s.control_every, s.record_every,
                      chunk_steps(s.record_every, s.control_every),
                      run.layout.continuous)  # fmt: skip


def batch_item(run) -> BatchItem:
    """The :class:`BatchItem` of a prepared slew (its arrays, not copies).

    Parameters
    ----------
    run : PreparedSlew
        The slew (:func:`flexsat.simulate.closedloop.prepare_slew`).

    Returns
    -------
    BatchItem
    """
    return BatchItem(run.x, slew_timing(run), run.stages, run.data, run.rec_t, run.rec_x,
                     run.rec_ctrl, run.rec_frame, run.rec_Q, run.rec_solved,
                     run.plant.packed, run.frame)  # fmt: skip


@njit(cache=True, nogil=True)
def fly(x, timing, stages, d, rec_t, rec_x, rec_ctrl, rec_frame, rec_Q, rec_solved, plant, frame,
        done, rows, max_chunks):  # fmt: skip
    """Advance a slew by up to ``max_chunks`` compiled chunks from step ``done``.

    Stops after the run's last step or at the first non-zero status.

    Parameters
    ----------
    x : ndarray, shape (x_size,)
        Plant state (q, q̇, work in, dissipated) [m, rad, m/s, rad/s, J], advanced in
        place.
    timing : SlewTiming
        The slew's clock.
    stages : LoopStages
        The compiled law and stages (:mod:`flexsat.simulate.loops`).
    d : LoopData
        The loop's arrays.
    rec_t : ndarray, shape (m,)
        Record times [s], written from row ``rows``.
    rec_x : ndarray, shape (m, x_size)
        Recorded plant states [m, rad, m/s, rad/s, J].
    rec_ctrl : ndarray, shape (m, record_size)
        Recorded control rows [SI units of each channel].
    rec_frame : ndarray, shape (m, 9)
        Recorded attitude references R_NF [-].
    rec_Q : ndarray, shape (m, n_dof)
        Recorded joint-actuator forces, hub columns zero [N, N m per coordinate].
    rec_solved : ndarray, shape (m, 2, n_dof)
        Recorded q_ddot and constraint forces, written where the loop has them
        (``LoopRecords.solved``) [m/s^2, rad/s^2; N, N m per coordinate].
    plant : PackedPlant
        The plant's named structure (``Plant.packed``).
    frame : ndarray, shape (9,)
        Attitude reference R_NF of ``x`` [-], updated in place.
    done : int
        Steps already taken.
    rows : int
        Record rows already written.
    max_chunks : int
        At most this many chunks in this call.

    Returns
    -------
    status, steps_done, rows_written : int
        Totals since the start of the run.
    """
    status = 0
    for _ in range(max_chunks):
        n_chunk = min(timing.chunk, timing.n_steps - done)
        final = done + n_chunk == timing.n_steps
        clock = LoopClock(done * timing.dt, timing.dt, n_chunk, final, timing.control_every,
                          timing.record_every, timing.continuous)  # fmt: skip
        status, ran, written = rk4_closed_loop(
            x, clock, stages, d,
            LoopRecords(rec_t, rec_x, rec_ctrl, rows, rec_frame, rec_Q, rec_solved), plant, frame,
        )  # fmt: skip
        done += ran
        rows += written
        if final or status != 0:
            break
    return status, done, rows


@njit(cache=True, nogil=True, parallel=True)
def fly_batch(items, out):
    """Fly every slew of a batch to its end, across the numba threads.

    Parameters
    ----------
    items : numba.typed.List of BatchItem
        Slews of one numba type, each flown on its own arrays.
    out : ndarray, shape (len(items), 3), int64
        Written: per slew, status, steps done, record rows written [-].
    """
    for i in prange(len(items)):
        it = items[np.int64(i)]  # the prange index is unsigned; the List takes int64
        status, done, rows = fly(it.x, it.timing, it.stages, it.data, it.rec_t, it.rec_x,
                                 it.rec_ctrl, it.rec_frame, it.rec_Q, it.rec_solved, it.plant,
                                 it.frame, 0, 0, it.timing.n_steps + 1)  # fmt: skip
        out[i, 0], out[i, 1], out[i, 2] = status, done, rows


_INT64 = (-(2**63), 2**63)  # numba types a Python int in this range as int64
_ITEM_TYPES: dict = {}  # structure key -> numba type of a BatchItem (one per structure)


def _structure_key(value) -> object:
    """What numba's ``typeof`` reads of ``value``, as a hashable key (cheap).

    An array: its dtype, dimensions, layout flags, writeability and alignment (what
    ``typeof`` makes its ``Array`` type of); a tuple: its class and its items' keys; an
    object that declares its numba type (``_numba_type_``, a
    :class:`~flexsat.compiled.first_class.FirstClassKernel`): that type; a float, a bool,
    an int within int64: its class. Anything else is typed by numba itself.
    """
    kind = type(value)
    if kind is np.ndarray:
        flags = value.flags
        return (value.dtype, value.ndim, flags.c_contiguous, flags.f_contiguous,
                flags.writeable, flags.aligned)  # fmt: skip
    if isinstance(value, tuple):
        return (kind, *(_structure_key(v) for v in value))
    numba_type = getattr(value, "_numba_type_", None)
    if numba_type is not None:
        return numba_type
    if kind is float or kind is bool or (kind is int and _INT64[0] <= value < _INT64[1]):
        return kind
    return typeof(value)


def item_type(item: BatchItem):
    """The numba type of a :class:`BatchItem`, typed once per structure.

    The same type as ``numba.typeof(item)``: items whose arrays, tuples and kernels
    agree in everything ``typeof`` reads (:func:`_structure_key`) share the type the
    first of them was given. Walking the item's ~140 leaves costs a tenth of typing
    them (``typeof`` goes through numba's typing of each array).

    Parameters
    ----------
    item : BatchItem
        A prepared slew.

    Returns
    -------
    numba.types.Type
    """
    key = _structure_key(item)
    found = _ITEM_TYPES.get(key)
    if found is None:
        found = _ITEM_TYPES[key] = typeof(item)
    return found


def _overload(dispatcher, *types):
    """The compiled entry point of ``dispatcher`` for argument types ``types``
    (compiled, or loaded from numba's cache, on first use): called without typing
    its arguments again."""
    if types not in dispatcher.overloads:
        dispatcher.compile(types)
    return dispatcher.overloads[types].entry_point


def fly_entry(item: BatchItem):
    """:func:`fly`'s compiled entry point for a slew's types, found without typing it.

    Called as ``fly`` is, with the slew's own arrays (:func:`batch_item`'s fields in
    order, then ``done``, ``rows`` and ``max_chunks`` as ints): the same machine code
    as ``fly(...)``, without the dispatcher typing every argument at each call (about
    a millisecond for a slew's hundred-odd arrays and kernels). The arguments must be
    of the item's types (:func:`item_type`); the entry point does not check them.

    Parameters
    ----------
    item : BatchItem
        The slew, as flown.

    Returns
    -------
    callable
        ``(x, timing, stages, d, rec_t, rec_x, rec_ctrl, rec_frame, rec_Q, rec_solved,
        plant, frame, done, rows, max_chunks) -> (status, steps_done, rows_written)``.
    """
    return _overload(fly, *item_type(item).types, types.int64, types.int64, types.int64)


def fly_whole(run) -> tuple[int, int, int]:
    """Fly a prepared slew to its end in one compiled call, in this thread.

    The call :func:`~flexsat.simulate.closedloop.run_slew` makes for a slew without a
    progress bar or a record stream (:func:`fly_entry`, every chunk in one call): the
    same records bit for bit.

    Parameters
    ----------
    run : PreparedSlew
        The slew (:func:`flexsat.simulate.closedloop.prepare_slew`), flown in place.

    Returns
    -------
    tuple of int
        Status (0: finished; else :mod:`flexsat.compiled.status`), steps done and
        record rows written [-].
    """
    item = batch_item(run)
    status, done, rows = fly_entry(item)(*item, 0, 0, item.timing.n_steps + 1)
    return int(status), int(done), int(rows)


def fly_prepared(runs: list, threads: int = 1) -> np.ndarray:
    """Fly prepared slews to their ends, those of one structure in one compiled call.

    Slews are grouped by the numba type of their :class:`BatchItem` (law, stage
    chains, appendage groups; :func:`item_type`): each group is one call of
    :func:`fly_batch` across ``threads`` numba threads (set for the calling thread
    only).

    Parameters
    ----------
    runs : list of PreparedSlew
        The slews (:func:`flexsat.simulate.closedloop.prepare_slew`), flown in place.
    threads : int
        numba threads across the slews of a group.

    Returns
    -------
    ndarray, shape (len(runs), 3), int64
        Per slew, in the given order: status, steps done, record rows written [-].
    """
    groups: dict = {}
    for index, run in enumerate(runs):
        item = batch_item(run)
        groups.setdefault(item_type(item), []).append((index, item))
    out = np.zeros((len(runs), 3), dtype=np.int64)
    set_num_threads(max(1, min(threads, config.NUMBA_NUM_THREADS)))
    for kind, members in groups.items():
        # the compiled list and append for this item type, called without typing
        items = _overload(typed_list, kind)(members[0][1])
        append = _overload(typed_append, typeof(items), kind)
        for _, item in members[1:]:
            append(items, item)
        flown = np.zeros((len(members), 3), dtype=np.int64)
        fly_batch(items, flown)
        out[[index for index, _ in members]] = flown
    return out
