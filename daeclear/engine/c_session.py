"""The compiled IDA session: SUNDIALS IDA, the model's callbacks and the step loop in C, driven
through ctypes a few calls per segment (no Python per step); the same interface as the python
backend (:class:`daeclear.engine.session_base.Session`). How the library is built and what the
C driver does: docs/engine.md. Linear solvers (``linear_solver``): ``"reduced"`` (dense LU after
eliminating the position rows), ``"dense"`` (SUNDIALS'), ``"sparse"`` (sparse LU on the plan made at
code generation, :mod:`daeclear.engine.sparse_plan`), ``"superlu"`` (SUNDIALS' SuperLU_MT); ``"auto"``
picks sparse from ``SPARSE_MIN_STATES`` states on.
"""

from __future__ import annotations

import ctypes
import itertools
import logging
import time
from pathlib import Path
from typing import Any
from collections.abc import Sequence

import numpy as np

from ..core.automaton import Decision, PairState, Storm
from ..core.errors import DaeclearError
from .abi import (DC_CHUNK, DC_ERR_COLLAPSE, DC_ERR_MAXSTEPS, DC_EV_CONTACT, DC_EV_HELD, DC_EV_KIND, DC_EV_N,
                  DC_EV_WATCH, DC_ROOT, DC_TSTOP, LINEAR_SOLVER_CODES, STAT_KEYS)
from .build import BuildResult
from .c_handle import Handle, address, pointer, put_pooled, take_pooled
from .codegen import NormalizedModel
from .library import ModelLibrary
from .session_base import (
    FLAG_MAX_STEPS,
    FLAG_STEP_COLLAPSE,
    OWN_FLAG_NAMES,
    STORE_STATES,
    STORE_TIMES,
    Advance,
    AutoEvents,
    ChunkCallback,
    SessionBase,
    SessionOptions,
    StateLayout,
    output_rows,
)
from .sundials import SPARSE_LIBS

__all__ = ["CSession", "SPARSE_MIN_STATES"]

#: linear_solver="auto" uses the sparse LU from this many states on, the reduced dense LU below
#: (measured: benchmarks/bench_linear_solver.py, docs/performance.md).
SPARSE_MIN_STATES = 60
_LS_NAMES = {code: name for name, code in LINEAR_SOLVER_CODES.items()}
log = logging.getLogger("daeclear")


def _resolve_linear_solver(requested: str, n: int, has_superlu: bool, has_plan: bool = True) -> str:
    """The linear solver a compiled session uses: "auto" is the sparse LU from SPARSE_MIN_STATES states
    on (when the model has a sparse plan), the reduced dense LU below."""
    if requested == "auto":
        return "sparse" if has_plan and n >= SPARSE_MIN_STATES else "reduced"
    if requested == "superlu" and not has_superlu:
        raise DaeclearError("linear_solver='superlu' is not available: the scikit-sundae wheel lacks "
                            f"lib{SPARSE_LIBS[0]} or lib{SPARSE_LIBS[1]}; use 'sparse', 'dense' or 'auto'")
    if requested == "sparse" and not has_plan:
        raise DaeclearError("linear_solver='sparse' is not available for this model: its Newton matrix has a "
                            "multiplier whose pivot no elimination fills (structurally singular static pivots); "
                            "use 'dense', 'reduced' or 'auto'")
    return requested


class CSession(SessionBase):
    """Compiled backend: IDA, callbacks and the step loop in C (see module docstring)."""

    backend = "c"

    def __init__(self, model: NormalizedModel, opts: SessionOptions, clib: ModelLibrary, build: BuildResult) -> None:
        super().__init__(model, opts)
        n, nt, nr, npar = clib.model_info(self._nt)
        if (n, nt, nr, tuple(npar)) != (model.n, self._nt, model.n_roots, model.n_params) \
                or clib.lib.dc_n_parameters() != model.n_parameters:
            raise DaeclearError(
                f"compiled library {clib.path} does not match the model: (n, terms, roots, params) = "
                f"{(n, nt, nr, npar)} != {(model.n, self._nt, model.n_roots, list(model.n_params))}"
            )
        self._clib = clib
        self._lib = clib.lib
        self._build = build
        self._nj = model.n_jac  # the iteration matrix's size (n / blocks: the stacked sensitivities')
        self._linear_solver = _resolve_linear_solver(opts.linear_solver, self._nj, clib.build_info.has_sparse,
                                                     clib.sparse_plan[0])
        hd = take_pooled(self._pool_key(), opts)
        if hd is None:
            hd = self._open(opts, n, nr)  # "auto" may fall back from the sparse LU to the reduced one
        self._hd = hd
        self._h, self._jac_nnz, self._cap, self._cap_times = hd.h, hd.jac_nnz, hd.cap, hd.cap_times
        self._st, self._sh, self._sord = hd.st, hd.sh, hd.sord
        self._yout, self._ypout, self._roots, self._statbuf = hd.yout, hd.ypout, hd.roots, hd.statbuf
        self._i_eval, self._n_stored, self._t_out, self._flag = hd.i_eval, hd.n_stored, hd.t_out, hd.flag
        self._y0b, self._yp0b, self._actb, self._rdb, self._pcat = hd.y0b, hd.yp0b, hd.actb, hd.rdb, hd.pcat
        self._addr = hd.addr
        self._extra_meta = hd.extra_meta
        self._poff = list(itertools.accumulate(model.n_params, initial=0))
        self._auto_storms: tuple[Storm, ...] = ()  # the storm constants of the pairs C decides (set_auto_events)

    def _pool_key(self) -> tuple[int, str, int, int]:
        """What a pooled handle must share with this session: library, linear solver, max_order, buffer_steps."""
        return id(self._lib), self._linear_solver, self._opts.max_order, self._opts.buffer_steps

    def _open(self, opts: SessionOptions, n: int, nr: int) -> Handle:
        """A new C session (dc_open) with its buffers; the sparse solver falls back to the reduced
        LU when "auto" chose it and it cannot be set up."""
        err = ctypes.create_string_buffer(1024)

        def dc_open() -> Any:
            return self._lib.dc_open(opts.rtol, opts.atol.ctypes.data, opts.max_step, opts.max_order,
                                     opts.max_steps, pointer(opts.root_directions), pointer(opts.parameters),
                                     LINEAR_SOLVER_CODES[self._linear_solver], err, 1024)

        h = dc_open()
        if not h and self._linear_solver == "sparse" and opts.linear_solver == "auto":
            log.info("daeclear: sparse linear solver unavailable, using the reduced dense LU: %s",
                     err.value.decode())
            self._linear_solver = "reduced"
            h = dc_open()
        if not h:
            raise DaeclearError(f"opening the compiled IDA session failed: {err.value.decode()}")
        return Handle(self._lib, h, n, nr, self._nt, sum(self._model.n_params), opts.buffer_steps)

    def set_hints(self, *, nonlin_conv_coef: float | None = None, jacobian_refresh: float | None = None,
                  first_step: bool | None = None) -> bool:
        """Solver hints: Newton convergence factor (IDA default 0.33), the relative change of cj
        from which IDA evaluates a new Jacobian (IDA default 0.25) and whether the run's first
        step is the second-order estimate of ida_driver.c's first_step (else IDA's own). Returns
        True (the compiled backend applies them)."""
        self._check_open()
        if nonlin_conv_coef is not None and self._lib.dc_set_nonlin_conv_coef(self._h, nonlin_conv_coef) < 0:
            raise DaeclearError(f"nonlin_conv_coef={nonlin_conv_coef!r} rejected by IDA; must be > 0.")
        if jacobian_refresh is not None and self._lib.dc_set_jacobian_refresh(self._h, jacobian_refresh) < 0:
            raise DaeclearError(f"jacobian_refresh={jacobian_refresh!r} rejected by IDA; must be >= 0.")
        if first_step is not None:
            self._lib.dc_set_first_step(self._h, int(first_step))
        return True

    def set_auto_events(self, pairs: Sequence[tuple[int, int, int, bool, float]], *, storms: Sequence[Storm],
                        states: Sequence[PairState], capacity: int = 256) -> bool:
        """Let the C loop decide every contact switch itself (after :meth:`set_layout`, see ida_driver.c).

        ``pairs``: (root index, term index, gap-rate extra, needs approach speed, min speed), one
        per root function; ``storms``: each pair's storm-guard constants; ``states``: each pair's
        :class:`daeclear.core.automaton.PairState` to start from (its history is not carried over).
        Each advance then returns the switches it made in ``Advance.auto_events``.
        """
        self._check_open()
        np_ = len(pairs)
        if len(storms) != np_ or len(states) != np_:
            raise ValueError(f"set_auto_events: {np_} pairs, {len(storms)} storms, {len(states)} states")
        capacity = max(int(capacity), np_)

        def arr(values: Any, dt: Any) -> np.ndarray:
            return np.ascontiguousarray(list(values) or [0], dtype=dt)

        rules = (tuple(pairs), tuple(storms))
        if self._hd.auto_rules is None or self._hd.auto_rules[0] != rules:  # a model's, kept on the handle (pooled)
            arrays = [arr((p[0] for p in pairs), np.int32), arr((p[1] for p in pairs), np.int32),
                      arr((p[2] for p in pairs), np.int32), arr((p[3] for p in pairs), np.int32),
                      arr((p[4] for p in pairs), np.float64), arr((st.events for st in storms), np.int32),
                      arr((st.window for st in storms), np.float64)]
            self._hd.auto_rules = (rules, arrays, [address(a) for a in arrays])
        starts = [arr((st.contact for st in states), np.int32), arr((st.held for st in states), np.int32),
                  arr((st.latched for st in states), np.float64)]
        self._auto_arrays = (self._hd.auto_rules[1], starts)  # alive while C reads them
        rc = self._lib.dc_set_auto(self._h, np_, *self._hd.auto_rules[2], *map(address, starts), capacity)
        if rc != 0:
            raise DaeclearError("configuring the events decided in C failed")
        self._auto_cap = capacity
        self._auto_storms = tuple(storms)
        if self._hd.auto_buf is None or self._hd.auto_buf[0][0].size != capacity:  # kept on the handle (pooled)
            buf = (np.empty(capacity), np.empty(capacity, dtype=np.int32),
                   np.empty((capacity, DC_EV_N), dtype=np.int32), np.empty(capacity), np.empty(capacity),
                   np.empty((capacity, self._n)))
            self._hd.auto_buf = (buf, tuple(address(a) for a in buf))
        self._auto_buf = self._hd.auto_buf
        return True

    def pair_states(self) -> list[PairState]:
        """The automaton state of every pair the C loop decides (:meth:`set_auto_events`'s order),
        read from C, which holds them: mode, hold, flight start, latched speed and switch history."""
        self._check_open()
        storms = self._auto_storms
        n = len(storms)
        ints = [np.zeros(max(n, 1), dtype=np.int32) for _ in range(3)]
        floats = [np.zeros(max(n, 1)) for _ in range(2)]
        recent = np.zeros(max(sum(st.events for st in storms), 1))
        contact, held, n_recent = ints
        free_since, latched = floats
        self._lib.dc_get_pairs(self._h, address(contact), address(held), address(free_since), address(latched),
                               address(n_recent), address(recent))
        out, offset = [], 0
        for p, storm in enumerate(storms):
            out.append(PairState(contact=bool(contact[p]), held=bool(held[p]), free_since=float(free_since[p]),
                                 latched=float(latched[p]),
                                 recent=tuple(recent[offset:offset + n_recent[p]].tolist())))
            offset += storm.events
        return out

    def set_kinematic_rows(self, n_kinematic: int) -> bool:
        """The reduced solver's eliminated position rows without a state layout (the stacked
        sensitivities' session factors the state's iteration matrix as the state's run does)."""
        self._check_open()
        if self._lib.dc_set_kinematic_rows(self._h, int(n_kinematic)) != 0:
            raise DaeclearError(f"set_kinematic_rows: n_kinematic={n_kinematic!r}, must be >= 0 and below the "
                                f"iteration matrix's {self._nj} rows.")
        return True

    def set_newton_tolerances(self, atol: np.ndarray | None) -> bool:
        """Newton's own convergence-test weights 1/(rtol |y| + atol) on the rows with ``atol > 0`` (a run's
        sensitivities out of IDA's error test, kept in Newton's: csrc/ida_newton.h); None: IDA's weights."""
        self._check_open()
        given = None
        if atol is not None:
            given = np.ascontiguousarray(atol, dtype=float)
            if given.shape != (self._n,):
                raise DaeclearError(f"set_newton_tolerances: atol of shape {given.shape}, must be ({self._n},)")
        if self._lib.dc_set_newton_atol(self._h, None if given is None else address(given)) != 0:
            raise DaeclearError(f"set_newton_tolerances failed: {self._lib.dc_message(self._h).decode()}")
        return True

    def set_layout(self, layout: StateLayout) -> bool:
        """The model's state layout and extras, so that C makes states consistent itself: restarts
        after the switches it decides (GGL: projected on the constraint manifold) and :meth:`report`."""
        self._check_open()
        L = layout
        rc = self._lib.dc_set_layout(self._h, L.n_q, L.n_constraints, int(L.ggl), int(L.track_work), L.accel_extra,
                                     L.force_extra0, L.kinematics_extra, L.outputs_extra, int(L.project), L.tol,
                                     L.max_iter)
        if rc != 0:
            raise DaeclearError("configuring the state layout of the compiled model failed")
        self._n_channels = L.n_channels
        return True

    def report(self, t: np.ndarray, y: np.ndarray, switch: np.ndarray, *,
               into: tuple[np.ndarray, np.ndarray] | None = None,
               channels: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The reported points made consistent in one C pass: (y with recomputed multipliers and yp,
        one row per time; the output channels, one contiguous row per channel; see ``dc_report``),
        after :meth:`set_layout`. ``into``: the caller's own (y, yp) arrays to write them to (y may be
        the ``y`` given), float64 and C-contiguous of shape (times, n): a run's output made no copy.
        ``channels=False``: states only (the channels come back with no row; a Result computes them when read)."""
        self._check_open()
        t = np.ascontiguousarray(t, dtype=float)
        y = np.ascontiguousarray(y, dtype=float)
        switch = np.ascontiguousarray(switch, dtype=float)
        N = t.size
        if into is None:
            y_out, yp_out = np.empty((N, self._n)), np.empty((N, self._n))
        else:
            y_out, yp_out = into
            for a in into:
                if a.shape != (N, self._n) or a.dtype != np.float64 or not (a.flags.c_contiguous and a.flags.writeable):
                    raise ValueError(f"report: into holds a {a.dtype} array of shape {a.shape}; each must be a "
                                     f"writable C-contiguous float64 array of shape ({N}, {self._n})")
        values = np.empty((self._n_channels, N) if channels else (0, N))
        if N and self._lib.dc_report(self._h, N, address(t), address(y), address(switch), address(y_out),
                                     address(yp_out), address(values) if channels else None) != 0:
            raise DaeclearError("making the reported points consistent in the compiled model failed")
        return y_out, yp_out, values

    def _take_auto_events(self) -> AutoEvents | None:
        buf = getattr(self, "_auto_buf", None)
        if buf is None:
            return None
        (t, pair, info, rate, latched, y), addresses = buf
        k = self._lib.dc_take_events(self._h, self._auto_cap, *addresses)
        if not k:
            return None
        return AutoEvents(t[:k].copy(), pair[:k].copy(), info[:k].copy(), rate[:k].copy(), latched[:k].copy(),
                          y[:k].copy())

    def automaton_run(self, times: Sequence[float], directions: Sequence[int], rates: Sequence[float], *,
                      storm: Storm, min_approach_speed: float, contact: bool = False, held: bool = False,
                      latched: float = 0.0) -> list[Decision]:
        """Run the compiled loop's pair automaton over a root sequence from the given state with no
        history (a test hook: the decisions must be those of :func:`daeclear.core.automaton.step`)."""
        t = np.ascontiguousarray(times, dtype=np.float64)
        d = np.ascontiguousarray(directions, dtype=np.int32)
        r = np.ascontiguousarray(rates, dtype=np.float64)
        n = t.size
        if d.size != n or r.size != n:
            raise ValueError("automaton_run: times, directions and rates differ in length")
        out_i = np.zeros((DC_EV_N, max(n, 1)), dtype=np.int32)  # an event's info columns, one row each
        out_l = np.zeros(max(n, 1))
        rows = (out_i[j].ctypes.data for j in (DC_EV_KIND, DC_EV_CONTACT, DC_EV_HELD, DC_EV_WATCH))
        rc = self._lib.dc_automaton_run(n, t.ctypes.data, d.ctypes.data, r.ctypes.data, storm.events,
                                        float(storm.window), float(min_approach_speed), int(contact), int(held),
                                        float(latched), *rows, out_l.ctypes.data)
        if rc != 0:
            raise DaeclearError("dc_automaton_run rejected its arguments")
        return [Decision(int(out_i[DC_EV_KIND, i]), bool(out_i[DC_EV_CONTACT, i]), bool(out_i[DC_EV_HELD, i]),
                         float(out_l[i]), int(out_i[DC_EV_WATCH, i])) for i in range(n)]

    def _terms_in_c(self) -> tuple[np.ndarray, np.ndarray]:
        """The C loop's active flags (one per term) and its terms' parameters, concatenated (dc_get_active)."""
        self._check_open()
        act = np.zeros(max(self._nt, 1), dtype=np.int32)
        par = np.zeros(max(self._poff[-1], 1))
        self._lib.dc_get_active(self._h, address(act), address(par))
        return act[:self._nt], par[:self._poff[-1]]

    def active_terms(self) -> tuple[list[bool], list[np.ndarray]]:
        """The active flags and parameters the C loop integrates with now."""
        act, par = self._terms_in_c()
        off = self._poff
        return [bool(a) for a in act], [par[off[k]:off[k + 1]].copy() for k in range(self._nt)]

    def active_switch(self) -> np.ndarray:
        """:meth:`active_terms` as a switch vector (each term's flag, then its parameters: the outputs'
        ``switch`` input, :meth:`daeclear.assembly.dae_model.DAEModel.switch_vector`)."""
        act, par = self._terms_in_c()
        nt = self._nt
        if self._hd.switch_columns is None:  # the library's, kept on the handle (pooled)
            off = self._poff  # term k: its flag after the earlier terms' columns, then its parameters
            self._hd.switch_columns = (np.array([k + off[k] for k in range(nt)], dtype=np.intp),
                                       np.array([k + 1 + j for k in range(nt) for j in range(off[k], off[k + 1])],
                                                dtype=np.intp))
        flags, params = self._hd.switch_columns
        switch = np.empty(nt + par.size)
        switch[flags] = act != 0
        switch[params] = par
        return switch

    def eval_extra(self, k: int, inputs: Sequence[np.ndarray], n_points: int) -> np.ndarray:
        inputs = [*inputs, self._opts.parameters]
        meta = self._extra_meta.get(k)
        if meta is None:  # input sizes, output size and reusable ctypes arrays, once per function and handle
            f = self._model.extras[k]
            sizes = [f.numel_in(j) for j in range(f.n_in())]
            meta = (sizes, f.numel_out(0), (ctypes.c_void_p * max(len(sizes), 1))(),
                    (ctypes.c_int * max(len(sizes), 1))())
            self._extra_meta[k] = meta
        sizes, n_out, ptrs, strides = meta
        keep = []
        for j, x in enumerate(inputs):
            a = x if (type(x) is np.ndarray and x.dtype == np.float64 and x.flags.c_contiguous) \
                else np.ascontiguousarray(x, dtype=float)
            size = sizes[j]
            if a.size == size:
                strides[j] = 0
            elif a.size == n_points * size:
                strides[j] = size
            else:
                raise ValueError(f"eval_extra({k}): input {j} has shape {a.shape}, "
                                 f"expected ({n_points}, {size}) or ({size},)")
            ptrs[j] = a.__array_interface__["data"][0]  # often read-only (P, a result's rows)
            keep.append(a)
        out = np.empty((n_points, n_out))
        rc = self._lib.dc_eval_extra(k, n_points, len(sizes), ptrs, strides, out.__array_interface__["data"][0], n_out)
        if rc != 0:
            raise DaeclearError(f"evaluating {self._model.extras[k].name()} in the compiled model failed "
                                f"(status {rc}).")
        return out

    # ---------------------------------------------------------------- core
    def _load_terms(self, act: np.ndarray, plist: list[np.ndarray]) -> None:
        nt = self._nt
        if nt:
            self._actb[:nt] = act
            off = self._poff
            for k in range(nt):
                if off[k + 1] > off[k]:
                    self._pcat[off[k]:off[k + 1]] = plist[k]

    def reinit(self, t0: float, y0: np.ndarray, yp0: np.ndarray, active: Sequence[bool],
               params: Sequence[np.ndarray], root_directions: np.ndarray | None = None) -> None:
        t0, y0, yp0, act, plist, rd = self._check_reinit(t0, y0, yp0, active, params, root_directions)
        A = self._addr
        self._y0b[:] = y0
        self._yp0b[:] = yp0
        self._load_terms(act, plist)
        if self.n_roots:
            self._rdb[:] = rd
        rc = self._lib.dc_reinit(self._h, t0, A["y0b"], A["yp0b"], A["actb"], A["pcat"], A["rdb"])
        if rc != 0:
            self._ready = False
            raise DaeclearError(f"IDA reinit failed: {self._lib.dc_message(self._h).decode()}")
        self._t, self._y, self._yp = t0, self._y0b.copy(), self._yp0b.copy()
        self._eval_after: float | None = None  # the C side drops a step cut short (dc_reinit)
        self._active = act
        self._params = plist
        self._ready = True

    def advance(self, t_stop: float, t_eval: np.ndarray | None = None,
                store_steps: bool = True, on_chunk: ChunkCallback | None = None, store_states: bool = True,
                chunked: bool = False, store_yp: bool = True) -> Advance:
        t_stop = self._check_advance(t_stop)
        n = self._n
        te = self._select_eval(t_eval, t_stop)
        m = te.size
        ev_y = np.empty((m, n))
        ev_yp = np.empty((m, n)) if store_yp else None  # None: the C loop computes no yp at the output times
        te_p, evy_p = (address(te), address(ev_y)) if m else (None, None)
        evyp_p = address(ev_yp) if m and ev_yp is not None else None
        A = self._addr
        self._i_eval.value = 0
        chunks: list[tuple[Any, ...]] = []  # step times, y, yp (None unless store_yp), sizes, orders
        auto_events: list[AutoEvents] = []
        store = (STORE_TIMES | (STORE_STATES if store_states else 0)) if store_steps else 0
        # times only: the long buffers; without any steps cap counts IDA calls (a streamed run hands
        # its events over every buffer_steps calls, so its memory does not grow with its length)
        cap = self._cap_times if store == STORE_TIMES else self._cap
        lib, h = self._lib, self._h
        tic = time.perf_counter()
        interrupted = False
        try:
            while True:
                sy, syp = self._state_buffers(store & STORE_STATES, store_yp)
                sy_p, syp_p = (None if b is None else address(b) for b in (sy, syp))
                rc = lib.dc_advance(h, t_stop, te_p, m, A["i_eval"], evy_p, evyp_p,
                                    store, cap, A["st"], sy_p, syp_p, A["sh"], A["sord"],
                                    A["n_stored"], A["t_out"], A["yout"], A["ypout"], A["roots"],
                                    A["flag"])
                k = self._n_stored.value
                states = (self._state_rows(sy, k, "sy"), self._state_rows(syp, k, "syp")) if sy is not None \
                    else (np.empty((0, n)), np.empty((0, n)) if store_yp else None)
                if k:
                    chunks.append((self._st[:k].copy(), *states, self._sh[:k].copy(), self._sord[:k].copy()))
                taken = self._take_auto_events()  # drained at every chunk: the C buffer never overflows
                if taken is not None:
                    auto_events.append(taken)
                if rc != 0 or chunked:
                    break
                # buffer full: back in Python between chunks, so Ctrl-C works here
                if on_chunk is not None:  # time reached, and contact switches made in C so far
                    on_chunk(self._t_out.value, sum(len(a) for a in auto_events))
        except KeyboardInterrupt:  # between chunks: return the steps taken so far, marked "interrupted"
            interrupted, rc = True, 1
        finally:
            self._solve_time += time.perf_counter() - tic
            # also after an interrupt between chunks: the C side stopped at a valid state
            self._t = self._t_out.value
            self._y = self._yout.copy()  # shared with the Advance: the session only reads it
            self._yp = self._ypout.copy()
        if len(chunks) == 1:
            st, sy, syp, sh, so = chunks[0]
        elif chunks:
            st, sy, sh, so = (np.concatenate([c[i] for c in chunks]) for i in (0, 1, 3, 4))
            syp = np.concatenate([c[2] for c in chunks]) if store_yp else None
        else:
            st, sy, syp, sh, so = np.empty(0), np.empty((0, n)), np.empty((0, n)), np.empty(0), np.empty(0, np.int32)
        ne = self._i_eval.value
        # the C loop stopped inside a step that has output times after the last row (see dc_advance)
        self._eval_after = float(te[-1]) if rc == DC_CHUNK and m and ne == m and te[-1] < self._t else None
        adv = Advance(status="tstop", t=self._t, y=self._y, yp=self._yp, step_t=st,
                      step_y=sy, step_yp=syp if store_yp else None, step_h=sh, step_order=so,
                      eval_t=te[:ne].copy(), eval_y=output_rows(ev_y, ne),
                      eval_yp=None if ev_yp is None else output_rows(ev_yp, ne),
                      auto_events=AutoEvents.join(auto_events))
        if interrupted:
            adv.status = "interrupted"
            return adv
        if rc == DC_CHUNK:  # chunked: a buffer is full, the integration goes on at the next call
            adv.status = "chunk"
            return adv
        if rc == DC_TSTOP:
            return adv
        if rc == DC_ROOT:
            adv.status = "root"
            adv.roots_found = self._roots[: self.n_roots].copy()
            return adv
        adv.status = "error"
        msg = self._lib.dc_message(h).decode()
        if rc == DC_ERR_MAXSTEPS:
            adv.flag, adv.flag_name = FLAG_MAX_STEPS, OWN_FLAG_NAMES[FLAG_MAX_STEPS]
        elif rc == DC_ERR_COLLAPSE:
            adv.flag, adv.flag_name = FLAG_STEP_COLLAPSE, OWN_FLAG_NAMES[FLAG_STEP_COLLAPSE]
        else:
            adv.flag = self._flag.value
            adv.flag_name = self._clib.flag_name(adv.flag) if adv.flag else "DC_USAGE"
        adv.message = msg
        return adv

    def _state_buffers(self, states: int, store_yp: bool) -> tuple[np.ndarray | None, np.ndarray | None]:
        """The buffers the next dc_advance writes the steps' y (and yp when ``store_yp``) into: the handle's
        spare ones, else new ones (the C loop writes each row once; :meth:`_state_rows` hands them on)."""
        if not states:
            return None, None
        hd, shape = self._hd, (self._cap, self._n)
        sy = hd.sy if hd.sy is not None else np.empty(shape)
        syp = (hd.syp if hd.syp is not None else np.empty(shape)) if store_yp else None
        hd.sy = hd.syp = None  # taken; given back by _state_rows when only a few rows were written
        return sy, syp

    def _state_rows(self, buf: np.ndarray | None, k: int, spare: str) -> np.ndarray | None:
        """The ``k`` rows the C loop wrote into ``buf``: a view of it when they fill half of it or more (no
        copy: the buffer is the rows' now), else a copy, and the buffer kept for the next call (so a view
        never holds more than twice its rows' memory)."""
        if buf is None:
            return None
        if k and 2 * k >= buf.shape[0]:
            return buf[:k]
        setattr(self._hd, spare, buf)
        return buf[:k].copy()

    # ---------------------------------------------------------------- model evaluation
    def residual(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._check_open()
        y, yp = self._vec(y, "y"), self._vec(yp, "yp")
        out = np.empty(self._n)
        self._sync_terms()
        if self._lib.dc_eval_residual(self._h, float(t), y.ctypes.data, yp.ctypes.data, out.ctypes.data):
            raise DaeclearError(f"the generated residual failed at t={t}")
        return out

    def sparse_jacobian(self, t: float, y: np.ndarray, yp: np.ndarray,
                        cj: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The iteration matrix as the sparse solver sees it: CSC (data, row indices, column
        pointers) on the union of the base and all term Jacobians' patterns (explicit zeros for
        inactive terms), whatever the session's linear solver."""
        self._check_open()
        y, yp = self._vec(y, "y"), self._vec(yp, "yp")
        colptr = np.empty(self._nj + 1, dtype=np.int64)
        rowind = np.empty(max(self._jac_nnz, 1), dtype=np.int64)
        data = np.empty(max(self._jac_nnz, 1))
        self._lib.dc_jac_pattern(self._h, colptr.ctypes.data, rowind.ctypes.data)
        self._sync_terms()
        if self._lib.dc_eval_jacobian_sparse(self._h, float(t), y.ctypes.data, yp.ctypes.data, float(cj),
                                             data.ctypes.data):
            raise DaeclearError(f"the generated Jacobian failed at t={t}")
        return data[:self._jac_nnz], rowind[:self._jac_nnz], colptr

    def jacobian(self, t: float, y: np.ndarray, yp: np.ndarray, cj: float) -> np.ndarray:
        self._check_open()
        y, yp = self._vec(y, "y"), self._vec(yp, "yp")
        out = np.empty((self._nj, self._nj), order="F")
        self._sync_terms()
        if self._lib.dc_eval_jacobian(self._h, float(t), y.ctypes.data, yp.ctypes.data, float(cj),
                                      out.ctypes.data):
            raise DaeclearError(f"the generated Jacobian failed at t={t}")
        return np.ascontiguousarray(out)

    def solve_linear(self, t: float, y: np.ndarray, yp: np.ndarray, cj: float, b: np.ndarray, *, solver: str,
                     n_kinematic: int = 0, matrix: np.ndarray | None = None) -> tuple[np.ndarray, int]:
        """X with J X = B (b: n values, or n x k for k right-hand sides), J the iteration matrix at
        (t, y, yp, cj) or the given n x n ``matrix``, by a new linear solver of the kind IDA uses:
        ``solver`` "dense", "reduced" (the first ``n_kinematic`` rows eliminated) or "sparse" (the
        model's plan; ``matrix`` zero outside the union pattern); and how many times the sparse LU
        fell back to dense LU. A check of the solvers against a plain LU."""
        self._check_open()
        y, yp = self._vec(y, "y"), self._vec(yp, "yp")
        B = np.array(b, dtype=float, order="F")
        nj = self._nj
        if B.shape[0] != nj or B.ndim > 2:
            raise ValueError(f"solve_linear: b has shape {B.shape}, must be ({nj},) or ({nj}, k)")
        A = None if matrix is None else np.asfortranarray(matrix, dtype=float)
        if A is not None and A.shape != (nj, nj):
            raise ValueError(f"solve_linear: matrix has shape {A.shape}, must be ({nj}, {nj})")
        if solver not in ("dense", "reduced", "sparse"):
            raise ValueError(f"solve_linear: solver={solver!r}, must be 'dense', 'reduced' or 'sparse'")
        self._sync_terms()
        info = np.zeros(1, dtype=np.int64)
        rc = self._lib.dc_solve_linear(self._h, LINEAR_SOLVER_CODES[solver], int(n_kinematic), float(t),
                                       y.ctypes.data, yp.ctypes.data, float(cj), None if A is None else A.ctypes.data,
                                       B.ctypes.data, 1 if B.ndim == 1 else B.shape[1], info.ctypes.data)
        if rc:
            why = {1: "singular", -2: "the matrix has a nonzero outside the union pattern",
                   -3: "the model has no sparse plan"}.get(rc, "error")
            raise DaeclearError(f"the {solver} linear solve failed at t={t} ({why})")
        return B, int(info[0])

    def solve_reduced(self, t: float, y: np.ndarray, yp: np.ndarray, cj: float, b: np.ndarray,
                      n_kinematic: int, matrix: np.ndarray | None = None) -> np.ndarray:
        """x with J x = b by the "reduced" linear solver with the first ``n_kinematic`` rows eliminated
        (:meth:`solve_linear`)."""
        return self.solve_linear(t, y, yp, cj, b, solver="reduced", n_kinematic=n_kinematic, matrix=matrix)[0]

    def roots(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._check_open()
        y, yp = self._vec(y, "y"), self._vec(yp, "yp")
        out = np.empty(self.n_roots)
        if self.n_roots and self._lib.dc_eval_roots(self._h, float(t), y.ctypes.data, yp.ctypes.data,
                                                    out.ctypes.data):
            raise DaeclearError(f"the generated root function failed at t={t}")
        return out

    def set_terms(self, active: Sequence[bool], params: Sequence[np.ndarray]) -> None:
        """Set active terms and parameters without restarting IDA (for residual/jacobian checks).

        The next advance() without reinit() integrates with them; prefer reinit() in event logic.
        """
        _, _, _, act, plist, _ = self._check_reinit(self._t, self._y, self._yp, active, params, None)
        self._active, self._params = act, plist
        self._sync_terms()

    def _sync_terms(self) -> None:
        self._load_terms(self._active, self._params)
        self._lib.dc_set_terms(self._h, self._addr["actb"], self._addr["pcat"])

    # ---------------------------------------------------------------- stats and lifetime
    def stats(self) -> dict[str, int | float | str]:
        self._check_open()
        self._lib.dc_stats(self._h, address(self._statbuf))
        out: dict[str, int | float | str] = {k: int(v) for k, v in zip(STAT_KEYS, self._statbuf)}
        out["solve_time"] = self._solve_time
        out["compile_time"] = self._build.compile_time
        out["codegen_time"] = self._build.codegen_time
        out["cache_hit"] = bool(self._build.cache_hit)
        out["linear_solver"] = _LS_NAMES[self._lib.dc_linear_solver(self._h)]
        out["jac_nnz"] = self._jac_nnz
        out["first_step"] = float(self._lib.dc_first_step(self._h))  # tried after the latest (re)start
        return out

    @property
    def linear_solver(self) -> str:
        """"reduced", "dense", "sparse" or "superlu": the LU IDA's Newton iteration uses in this session."""
        return self._linear_solver

    @property
    def library_path(self) -> Path:
        return self._build.path

    @property
    def cache_hit(self) -> bool:
        return self._build.cache_hit

    @property
    def sundials_version(self) -> str:
        return self._clib.sundials_version

    def close(self) -> None:
        """Close the session: its C session goes to the pool of this library's sessions (the next
        session takes it with dc_reset instead of dc_open) or, the pool full, is freed."""
        if not self._closed:
            self._closed = True
            put_pooled(self._pool_key(), self._hd)
