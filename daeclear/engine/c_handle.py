"""One compiled C session (``dc_open``) with the buffers its loop fills, and the pool that hands it on:
a closed :class:`daeclear.engine.c_session.CSession` leaves its :class:`Handle` to the next session of
the same library and settings, re-armed by ``dc_reset`` (step for step as a new one; dc_open and
dc_free cost more than the Python around a short run).
"""

from __future__ import annotations

import ctypes
import logging
import weakref
from typing import Any

import numpy as np

from .abi import DC_ST_N
from .build import memo_put_bounded, memo_table
from .session_base import SessionOptions

log = logging.getLogger("daeclear")
_char_at = ctypes.c_char.from_buffer


def address(a: np.ndarray) -> int:
    """The address of a contiguous array's data (a ctypes view of its buffer costs a quarter of
    ``a.ctypes.data``, which a read-only array takes)."""
    try:
        return ctypes.addressof(_char_at(a))  # type: ignore[arg-type]  # an ndarray is a buffer
    except (TypeError, ValueError, BufferError):
        return a.ctypes.data


def pointer(a: np.ndarray | None) -> int | None:
    return None if a is None or a.size == 0 else address(a)


#: rows of the times-only step buffers (time, size, order) per row of the state buffers
TIMES_ROWS_PER_STATE_ROW = 16


class Handle:
    """One C session (dc_open) and the buffers its loop fills; freed when collected."""

    def __init__(self, lib: Any, h: int, n: int, nr: int, nt: int, n_params: int, buffer_steps: int) -> None:
        self.lib, self.h = lib, h
        weakref.finalize(self, lib.dc_free, h)
        self.jac_nnz = int(lib.dc_jac_nnz(h))
        # rows of the step buffers: buffer_steps with states, TIMES_ROWS_PER_STATE_ROW times as many without
        self.cap = buffer_steps
        cap = self.cap_times = buffer_steps * TIMES_ROWS_PER_STATE_ROW
        self.st = np.empty(cap)
        # the steps' states: made at the first advance that stores them
        self.sy: np.ndarray | None = None
        self.syp: np.ndarray | None = None
        self.sh = np.empty(cap)
        self.sord = np.empty(cap, dtype=np.int32)
        self.yout = np.empty(n)
        self.ypout = np.empty(n)
        self.roots = np.zeros(max(nr, 1), dtype=np.int32)
        self.i_eval = ctypes.c_int()
        self.n_stored = ctypes.c_int()
        self.t_out = ctypes.c_double()
        self.flag = ctypes.c_int()
        self.statbuf = np.zeros(DC_ST_N, dtype=np.int64)
        # reinit inputs: copied into fixed arrays whose addresses are known
        self.y0b = np.zeros(n)
        self.yp0b = np.zeros(n)
        self.actb = np.zeros(max(nt, 1), dtype=np.int32)
        self.rdb = np.zeros(max(nr, 1), dtype=np.int32)
        self.pcat = np.zeros(max(n_params, 1))
        # set_auto_events' buffers and addresses; the switch vector's columns of the terms' flags and
        # parameters (active_switch); the latest pairs' rules ((pairs, storms), arrays, addresses)
        self.auto_buf: tuple[tuple[np.ndarray, ...], tuple[int, ...]] | None = None
        self.switch_columns: tuple[np.ndarray, np.ndarray] | None = None
        self.auto_rules: tuple[Any, list[np.ndarray], list[int]] | None = None
        # per extra: its input and output sizes and the ctypes arrays of its call (eval_extra)
        self.extra_meta: dict[int, tuple[Any, ...]] = {}
        self.addr = dict(
            st=self.st.ctypes.data, sy=None, syp=None,
            sh=self.sh.ctypes.data, sord=self.sord.ctypes.data, yout=self.yout.ctypes.data,
            ypout=self.ypout.ctypes.data, roots=self.roots.ctypes.data,
            i_eval=ctypes.addressof(self.i_eval), n_stored=ctypes.addressof(self.n_stored),
            t_out=ctypes.addressof(self.t_out), flag=ctypes.addressof(self.flag),
            y0b=self.y0b.ctypes.data, yp0b=self.yp0b.ctypes.data, actb=self.actb.ctypes.data,
            rdb=self.rdb.ctypes.data, pcat=self.pcat.ctypes.data,
        )


#: closed sessions' handles by (library, linear solver, max_order, buffer_steps): at most
#: POOL_PER_KEY each (threads running the same model at once), for the POOL_KEYS newest keys
POOL_PER_KEY = 2
POOL_KEYS = 4
_POOL: dict[tuple[int, str, int, int], list[Handle]] = memo_table()


def take_pooled(key: tuple[int, str, int, int], opts: SessionOptions) -> Handle | None:
    """A pooled handle re-armed with ``opts`` (dc_reset), or None (none pooled, or its reset failed)."""
    handles = _POOL.get(key)
    try:
        hd = handles.pop() if handles else None
    except IndexError:  # another thread took the last one
        return None
    if hd is not None and hd.lib.dc_reset(hd.h, opts.rtol, address(opts.atol), opts.max_step, opts.max_steps,
                                          pointer(opts.root_directions), pointer(opts.parameters)) != 0:
        log.info("daeclear: a pooled IDA session could not be reset (%s); opening a new one",
                 hd.lib.dc_message(hd.h).decode())
        return None  # freed when collected
    return hd


def put_pooled(key: tuple[int, str, int, int], hd: Handle) -> None:
    """Keep a closed session's handle for the next session (or drop it: freed when collected),
    without the steps' state buffers (the pool holds little more than IDA's memory)."""
    hd.sy = hd.syp = hd.addr["sy"] = hd.addr["syp"] = None
    handles = _POOL.get(key)
    if handles is None:
        handles = []
        memo_put_bounded(_POOL, key, handles, POOL_KEYS)
    if len(handles) < POOL_PER_KEY:
        handles.append(hd)
