"""The all-C bound of a ``simulate`` call (issue 35, item 6), side by side with the call itself.

    python benchmarks/bench_bound.py [--t-end 0.024] [--repeats 5] [--formulations index1 ggl] [--write-doc]

Scene: the chapter's slider-crank with the 0.5 mm revolute clearance joint and no gravity
(Fig. 4.15), two crank revolutions (0.024 s) at rtol 1e-8, every internal step reported (the
default output). For each formulation:

1. One ``simulate(scene, t_end, rtol=1e-8, formulation=f)`` call is made with the calls into
   the model library recorded (:class:`Recorder`): opening the session (tolerances, the atol
   vector, linear solver), the hints (Jacobian refresh, first step, Newton coefficient), the
   stall guard, the state layout, the consistent start state, the pairs whose switches the
   compiled loop decides, and the advance loop's stop time, store flags and buffer rows. They
   go to a setup file, in simulate's order, floats in hexadecimal (exact).
2. ``benchmarks/bound_main.c`` is compiled with the package's C compiler and run on that file:
   it opens the very library simulate used (the CasADi-generated functions and the package's
   IDA driver, built by ``daeclear.engine.codegen``) with dlopen, replays the calls and runs
   ``dc_advance`` to t_end, keeping every step's time and state and every event in arrays that
   grow, with no Python in the loop. Its stored steps, events and end state must be simulate's
   (printed; steps within 2 %, events equal, or the script exits with status 1).
3. Timing, interleaved in this process, best of --repeats: the C program's run (``bound_run``
   called through ctypes; its clock runs from ``dc_open`` to ``dc_free``), and the whole
   ``simulate(scene, ...)`` call with a new Scene object of the same numbers each time (set-up
   included; the structure compiled and cached beforehand, and simulate's session pool warm),
   their ratio, and the parts of the call: its IDA loop (``stats["solve_time"]``, the same C loop
   driven through ctypes), its set-up (``stats["setup_time"]``) and its report pass
   (``CSession.report``: the multipliers, accelerations and 43 channels of every step, what item 6
   removes), and the rest (recording the steps and events, the physics checks, the Result). The
   last column divides by the index-1 C run, as issue 35 states its targets
   (whole call within 1.3x of it with index-1, within 1.6x with the default GGL).

The C run does not compute the consistent start (Python does, once, for the setup file), which
is part of the simulate call. ``--write-doc`` writes the ratios, steps and events (deterministic,
checked by tests/test_doc_numbers.py) into docs/performance.md (block "bound").
"""

from __future__ import annotations

import argparse
import ctypes
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import daeclear as dc
from daeclear.engine.build import CSRC, compiler_command
from daeclear.engine.abi import STAT_KEYS
from daeclear.engine.c_session import CSession
from daeclear.engine.codegen import build_model_library, clear_memos
from daeclear.engine.library import DRIVER_ABI, ModelLibrary

REV = 60.0 / 5000.0
RTOL = 1e-8
SOURCE = Path(__file__).resolve().parent / "bound_main.c"
#: the driver interface bound_main.c is written for (its BOUND_ABI)
BOUND_ABI = 10
N_STATS = len(STAT_KEYS)  # the counters dc_stats writes
#: simulate's stored steps and the C program's may differ by this fraction (they are expected equal)
STEPS_TOLERANCE = 0.02


def scene() -> dc.Scene:
    """The Fig. 4.15 scene: revolute clearance 0.5 mm, 5000 rpm, no gravity."""
    return dc.mechanisms.slider_crank("revolute", gravity=0.0)


# --------------------------------------------------------------------------- recording simulate's calls


def _read(address: int | None, count: int, ctype: Any) -> list[float]:
    """``count`` values of ``ctype`` at ``address`` (none at a NULL pointer)."""
    if not address or count <= 0:
        return []
    return [float(x) for x in (ctype * count).from_address(address)]


@dataclass
class Recorder:
    """The calls a simulate call makes into its model library that set up and run the session.

    ``ops``: (name, numbers, arrays) in call order, as bound_main.c's setup file holds them;
    ``stored``: the steps each dc_advance call stored; ``codes``: what each dc_advance returned;
    ``reinits``: dc_reinit calls (one: the start; more would be restarts decided in Python).
    """

    n: int
    n_roots: int
    n_terms: int
    n_params: int
    n_parameters: int
    ops: list[tuple[str, list[float], list[list[float]]]] = field(default_factory=list)
    stored: list[int] = field(default_factory=list)
    codes: list[int] = field(default_factory=list)
    reinits: int = 0

    def wrappers(self) -> dict[str, Callable[[Callable[..., Any]], Callable[..., Any]]]:
        """name -> a function that wraps the library's function of that name."""
        n, nr, nt, npar, nP = self.n, self.n_roots, self.n_terms, self.n_params, self.n_parameters
        D, I = ctypes.c_double, ctypes.c_int

        def record(name: str, make: Callable[..., tuple[list[float], list[list[float]]]]) -> Any:
            def wrap(fn: Callable[..., Any]) -> Callable[..., Any]:
                def call(*args: Any) -> Any:
                    numbers, arrays = make(*args)
                    self.ops.append((name, numbers, arrays))
                    return fn(*args)
                return call
            return wrap

        def advance(fn: Callable[..., Any]) -> Callable[..., Any]:
            def call(*args: Any) -> Any:
                if not self.codes:
                    if args[3] != 0:
                        raise RuntimeError("bench_bound: simulate passed output times; the bound keeps every step")
                    self.ops.append(("advance", [args[1], args[7], args[8]], []))
                rc = fn(*args)
                self.codes.append(int(rc))
                self.stored.append(ctypes.c_int.from_address(args[14]).value)
                return rc
            return call

        def reinit(fn: Callable[..., Any]) -> Callable[..., Any]:
            def call(*args: Any) -> Any:
                self.reinits += 1
                if self.reinits == 1:
                    h, t0, y0, yp0, act, par, rd = args
                    self.ops.append(("reinit", [t0], [_read(y0, n, D), _read(yp0, n, D), _read(act, nt, I),
                                                     _read(par, npar, D), _read(rd, nr, I)]))
                return fn(*args)
            return call

        def auto(fn: Callable[..., Any]) -> Callable[..., Any]:
            def call(*args: Any) -> Any:
                h, k, *arrays, cap = args
                types = (I, I, I, I, D, I, D, I, I, D)
                self.ops.append(("auto", [k, cap], [_read(a, k, t) for a, t in zip(arrays, types)]))
                return fn(*args)
            return call

        return {
            "dc_open": record("open", lambda rtol, atol, max_step, max_order, max_steps, rd, P, ls, *_: (
                [rtol, max_step, max_order, max_steps, ls], [_read(atol, n, D), _read(rd, nr, I), _read(P, nP, D)])),
            "dc_reset": record("reset", lambda *_: ([], [])),  # a pooled session: refused below
            "dc_set_nonlin_conv_coef": record("nonlin_conv_coef", lambda h, x: ([x], [])),
            "dc_set_jacobian_refresh": record("jacobian_refresh", lambda h, x: ([x], [])),
            "dc_set_first_step": record("first_step", lambda h, on: ([on], [])),
            "dc_set_stall": record("stall", lambda h, step, count: ([step, count], [])),
            "dc_set_layout": record("layout", lambda h, nq, m, ggl, tw, acc, f0, kin, out, proj, tol, it: (
                [tol, nq, m, ggl, tw, acc, f0, kin, out, proj, it], [])),
            "dc_reinit": reinit,
            "dc_set_auto": auto,
            "dc_advance": advance,
        }

    def check(self) -> None:
        """The recorded run is one the C program can replay: a new session, one start, no root left to Python."""
        names = [op[0] for op in self.ops]
        if "reset" in names or names.count("open") != 1:
            raise RuntimeError(f"bench_bound: expected one dc_open and no pooled session, recorded {names}")
        if self.reinits != 1 or any(rc not in (0, 1) for rc in self.codes) or self.codes[-1:] != [1]:
            raise RuntimeError(f"bench_bound: simulate restarted from Python ({self.reinits} dc_reinit, dc_advance "
                               f"returned {sorted(set(self.codes))}): the C program replays runs whose every "
                               "contact switch the compiled loop decides")

    def write(self, path: Path) -> None:
        """The setup file of bound_main.c: "n <states> <roots>", then one line per call."""
        lines = [f"n {self.n} {self.n_roots}"]
        for name, numbers, arrays in self.ops:
            words = [name] + [_number(x, i, name) for i, x in enumerate(numbers)]
            for a in arrays:
                words += [str(len(a))] + [float(x).hex() for x in a]
            lines.append(" ".join(words))
        path.write_text("\n".join(lines) + "\n")


#: per op, how many of its leading numbers are floats (the rest are integers)
_FLOATS = {"open": 2, "nonlin_conv_coef": 1, "jacobian_refresh": 1, "first_step": 0, "stall": 1, "layout": 1,
           "reinit": 1, "auto": 0, "advance": 1}


def _number(x: float, i: int, op: str) -> str:
    return float(x).hex() if i < _FLOATS[op] else str(int(x))


@contextmanager
def recording(model: Any) -> Iterator[Recorder]:
    """Record the calls into the model's library while the block runs (the library's functions wrapped)."""
    clib = ModelLibrary.load(build_model_library(model.functions).path)
    n, nt, nr, n_params = clib.model_info(len(model.terms))
    rec = Recorder(n, nr, nt, sum(n_params), int(clib.lib.dc_n_parameters()))
    lib = clib.lib
    originals = {name: getattr(lib, name) for name in rec.wrappers()}
    clear_memos()  # no pooled session: the run opens its own with dc_open, as the C program does
    try:
        for name, wrap in rec.wrappers().items():
            setattr(lib, name, wrap(originals[name]))
        yield rec
    finally:
        for name, fn in originals.items():
            setattr(lib, name, fn)
    rec.check()


# --------------------------------------------------------------------------- the C program


@dataclass(frozen=True)
class Program:
    executable: Path
    shared: Path


def build_program(folder: Path) -> Program:
    """bound_main.c as an executable and as a shared library (bound_run, for ctypes), with the package's compiler."""
    if DRIVER_ABI != BOUND_ABI:
        raise RuntimeError(f"bench_bound: the driver interface is version {DRIVER_ABI}, bound_main.c follows "
                           f"version {BOUND_ABI}: update its calls (see csrc and daeclear.engine.library)")
    cc = compiler_command()
    exe, so = folder / "bound", folder / "libbound.so"
    inc = f"-I{CSRC}"  # dc_abi.h (return codes, stats slots) and dc_api.h (the dc_* declarations)
    for cmd in ([*cc, "-O2", inc, str(SOURCE), "-o", str(exe), "-ldl"],
                [*cc, "-O2", "-fPIC", "-shared", "-DBOUND_NO_MAIN", inc, str(SOURCE), "-o", str(so), "-ldl"]):
        subprocess.run(cmd, check=True, capture_output=True, text=True)
    return Program(exe, so)


@dataclass(frozen=True)
class BoundRun:
    wall: list[float]
    loop: list[float]
    steps: int
    events: int
    stats: list[int]
    t_end: float
    y_end: np.ndarray


def bound_run(program: Program, library: Path, setup: Path, repeats: int, n: int) -> BoundRun:
    """Run the C program's bound_run in this process ``repeats`` times."""
    lib = ctypes.CDLL(str(program.shared))
    fn = lib.bound_run
    fn.restype = ctypes.c_int
    times = (ctypes.c_double * (2 * repeats))()
    counts = (ctypes.c_longlong * (2 + N_STATS))()
    y_end = (ctypes.c_double * n)()
    t_end = ctypes.c_double()
    err = ctypes.create_string_buffer(512)
    rc = fn(str(library).encode(), str(setup).encode(), ctypes.c_int(repeats), times, counts, y_end,
            ctypes.c_int(n), ctypes.byref(t_end), err, ctypes.c_int(512))
    if rc != 0:
        raise RuntimeError(f"bench_bound: the C program failed: {err.value.decode()}")
    return BoundRun(list(times[0::2]), list(times[1::2]), int(counts[0]), int(counts[1]), list(counts[2:]),
                    t_end.value, np.array(y_end[:]))


# --------------------------------------------------------------------------- simulate, timed


class ReportClock:
    """Adds up the time spent in ``CSession.report`` (the report pass) while installed."""

    def __init__(self) -> None:
        self.total = 0.0

    @contextmanager
    def installed(self) -> Iterator[ReportClock]:
        original = getattr(CSession, "report", None)
        if original is None:  # no report pass any more: nothing to time
            yield self
            return

        def report(session: CSession, *args: Any, **kwargs: Any) -> Any:
            tic = time.perf_counter()
            try:
                return original(session, *args, **kwargs)
            finally:
                self.total += time.perf_counter() - tic

        CSession.report = report  # type: ignore[method-assign]
        try:
            yield self
        finally:
            CSession.report = original  # type: ignore[method-assign]


def timed_simulate(t_end: float, formulation: str) -> tuple[float, float, Any]:
    """(wall time of one simulate call on a new Scene, time of its report pass, its result)."""
    sc = scene()
    clock = ReportClock()
    with clock.installed():
        tic = time.perf_counter()
        result = dc.simulate(sc, t_end, rtol=RTOL, options=dc.SolverOptions(formulation=formulation))
        wall = time.perf_counter() - tic
    return wall, clock.total, result


# --------------------------------------------------------------------------- one formulation


@dataclass
class Comparison:
    """One formulation: the C run checked against simulate's, then the timed repeats of both."""

    formulation: str
    bound: BoundRun  # the checked C run (its time not counted)
    c_walls: list[float]  # the timed C runs, dc_open to dc_free
    c_loops: list[float]  # their advance loops
    walls: list[float]
    reports: list[float]
    solves: list[float]
    setups: list[float]
    steps: int
    events: int
    agree: list[str]
    counters_equal: bool  # every IDA counter (dc_stats) of the C run is simulate's: the very same run
    library: Path  # the model library simulate used
    setup: Path  # the recorded calls (bound_main.c's setup file)
    n_q: int  # coordinates (y = [q, v, ...])


def prepare(formulation: str, t_end: float, folder: Path) -> tuple[Path, Path, Any, Any]:
    """Build and warm the structure, record one simulate call: (library, setup file, recorder, result)."""
    model = dc.assemble(scene(), formulation)
    dc.simulate(scene(), t_end, rtol=RTOL,
                options=dc.SolverOptions(formulation=formulation))  # compiled and cached beforehand
    with recording(model) as rec:
        result = dc.simulate(scene(), t_end, rtol=RTOL, options=dc.SolverOptions(formulation=formulation))
    dc.simulate(scene(), t_end, rtol=RTOL,
                options=dc.SolverOptions(formulation=formulation))  # warm again: recording emptied the memos
    setup = folder / f"setup_{formulation}.txt"
    rec.write(setup)
    return build_model_library(model.functions).path, setup, rec, result


def agreement(bound: BoundRun, rec: Recorder, result: Any, n_q: int) -> list[str]:
    """What differs between the C program's run and simulate's (empty: the same run)."""
    problems = []
    py_steps = len(result.step_t) - 1  # the start row is not a step
    if sum(rec.stored) != py_steps:
        problems.append(f"simulate's recorded advance stored {sum(rec.stored)} steps but its result holds {py_steps}")
    if abs(bound.steps - py_steps) > STEPS_TOLERANCE * py_steps:
        problems.append(f"steps: C {bound.steps}, simulate {py_steps}")
    if bound.events != len(result.events):
        problems.append(f"events: C {bound.events}, simulate {len(result.events)}")
    if bound.t_end != result.t[-1]:
        problems.append(f"end time: C {bound.t_end!r}, simulate {result.t[-1]!r}")
    qv = result.y[-1, :2 * n_q]  # positions and velocities (the report pass recomputes the multipliers)
    scale = np.maximum(np.abs(qv), 1e-3)
    if not np.all(np.abs(bound.y_end[:2 * n_q] - qv) <= 1e-6 * scale):
        problems.append(f"end state (q, v) differs by up to {np.max(np.abs(bound.y_end[:2 * n_q] - qv) / scale):.2g}")
    return problems


def run_executable(program: Program, library: Path, setup: Path) -> str:
    """The standalone program's printout (one repeat): the same run outside Python."""
    out = subprocess.run([str(program.executable), str(library), str(setup), "1"], capture_output=True, text=True,
                         check=True)
    return out.stdout.strip()


def compare(formulations: list[str], t_end: float, repeats: int, folder: Path) -> list[Comparison]:
    """Record, replay in C and time each formulation side by side (interleaved repeats)."""
    program = build_program(folder)
    prepared = {f: prepare(f, t_end, folder) for f in formulations}
    out = []
    for f, (library, setup, rec, result) in prepared.items():
        n_q = next(op[1][1] for op in rec.ops if op[0] == "layout")
        first = bound_run(program, library, setup, 1, rec.n)
        print(f"{f}: standalone program: " + run_executable(program, library, setup).replace("\n", "; "))
        out.append(Comparison(f, first, [], [], [], [], [], [], len(result.step_t) - 1, len(result.events),
                              agreement(first, rec, result, int(n_q)),
                              first.stats == [result.stats[k] for k in STAT_KEYS], library, setup, int(n_q)))
    for _ in range(repeats):  # interleaved: C run, simulate call, for each formulation in turn
        for cmp in out:
            library, setup, rec, _result = prepared[cmp.formulation]
            run = bound_run(program, library, setup, 1, rec.n)
            cmp.c_walls.extend(run.wall)
            cmp.c_loops.extend(run.loop)
            wall, report, result = timed_simulate(t_end, cmp.formulation)
            cmp.walls.append(wall)
            cmp.reports.append(report)
            cmp.solves.append(result.stats["solve_time"])
            cmp.setups.append(result.stats["setup_time"])
    return out


def table(results: list[Comparison], t_end: float, repeats: int) -> list[str]:
    """The timings as a Markdown table: best of the repeats; the simulate call's parts are its best call's."""
    base = {r.formulation: min(r.c_walls) for r in results}.get("index1")
    lines = [f"Fig. 4.15 scene, t_end = {t_end:g} s, rtol {RTOL:g}, every step reported; best of {repeats}",
             "| formulation | steps | events | all-C run | simulate(scene) | its IDA loop | its set-up | "
             "its report pass | the rest | ratio | ratio to the index-1 all-C run |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in results:
        c = min(r.c_walls)
        best = int(np.argmin(r.walls))
        w, rep, loop, setup = r.walls[best], r.reports[best], r.solves[best], r.setups[best]
        lines.append(f"| {r.formulation} | {r.bound.steps} | {r.bound.events} | {c * 1e3:.1f} ms | {w * 1e3:.1f} ms | "
                     f"{loop * 1e3:.1f} ms | {setup * 1e3:.1f} ms | {rep * 1e3:.1f} ms ({rep / w:.0%}) | "
                     f"{(w - loop - setup - rep) * 1e3:.1f} ms | "
                     f"{w / c:.2f}x | " + (f"{w / base:.2f}x |" if base else "- |"))
    lines.append("(the all-C runs' dc_open, set-up calls and dc_free beyond their advance loops: " + ", ".join(
        f"{r.formulation} {(min(r.c_walls) - min(r.c_loops)) * 1e3:.2f} ms" for r in results) + ")")
    return lines


def doc_table(results: list[Comparison]) -> list[str]:
    """The ratios of --write-doc: the best call of each over the best all-C run."""
    base = {r.formulation: min(r.c_walls) for r in results}.get("index1")
    lines = ["| formulation | steps | events | `simulate(scene)` / all-C run | its IDA loop / all-C run | "
             "its set-up and the rest, share of the call | `simulate` / index-1 all-C run |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for r in results:
        c = min(r.c_walls)
        best = int(np.argmin(r.walls))
        w, loop = r.walls[best], r.solves[best]
        lines.append(f"| {r.formulation} | {r.bound.steps} | {r.bound.events} | {w / c:.2f} | {loop / c:.2f} | "
                     f"{(w - loop) / w:.0%} | " + (f"{w / base:.2f} |" if base else "- |"))
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=2 * REV, help="end time, s (two revolutions: 0.024)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--formulations", nargs="+", default=["index1", "ggl"], choices=["index1", "ggl"])
    parser.add_argument("--write-doc", action="store_true", help="write the ratios into docs/performance.md")
    args = parser.parse_args(argv)
    if not args.repeats >= 1:
        parser.error(f"--repeats={args.repeats}, must be >= 1")
    if not args.t_end > 0:
        parser.error(f"--t-end={args.t_end}, must be > 0")
    with tempfile.TemporaryDirectory(prefix="bench_bound-") as tmp:
        results = compare(args.formulations, args.t_end, args.repeats, Path(tmp))
    ok = True
    for r in results:
        print(f"{r.formulation}: C steps {r.bound.steps} events {r.bound.events}; simulate steps {r.steps} "
              f"events {r.events}; " + ("the same run" if not r.agree else "DIFFERENT: " + "; ".join(r.agree))
              + f" (IDA's counters {'all equal' if r.counters_equal else 'differ'})")
        ok = ok and not r.agree
    print("\n".join(table(results, args.t_end, args.repeats)))
    if args.write_doc and ok:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from doc_tables import write_block

        command = "python benchmarks/bench_bound.py" + (f" --repeats {args.repeats}" if args.repeats != 5 else "") + (
            f" --t-end {args.t_end:g}" if args.t_end != 2 * REV else "")
        print(f"wrote {write_block('docs/performance.md', 'bound', command, doc_table(results))}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
