"""How model size drives build time, generated code, solve time and memory: chains of N links.

The mechanism is ``daeclear.mechanisms.chain(N)``: N steel links hanging from the ground,
released from the horizontal, every pin (the ground pin too) a revolute clearance joint with
Lankarani-Nikravesh contact, so the model has 6 N states, N contact terms and N gap functions.

Each size is measured in its own child process with an EMPTY compiled-model cache
(``DAECLEAR_CACHE_DIR`` set to a fresh temporary directory, removed afterwards), so every
build is cold and no measurement sees another's libraries or memory:

* states: ``daeclear.assemble(scene).n_states``;
* C code: bytes of every ``*.c`` file that appeared in the fresh cache directory (the
  generated model sources kept next to the libraries; a build killed by the timeout still
  leaves its source in its private build directory there, so the size is known then too);
* build: wall time of the first ``simulate(scene, 1e-4)`` (empty cache: assembly, code
  generation, compilation) minus the best of two identical warm calls (cache filled);
* cc: the compiler time the run reports in ``result.stats["compile_time"]`` (if it does);
* solve: best wall time of ``simulate(scene, t_end)`` over ``--repeats`` warm calls (Scene in,
  so assembly and set-up included), per simulated second;
* RSS: peak resident memory of the child (``ru_maxrss``); of its largest finished descendant
  (``RUSAGE_CHILDREN``; on Linux never below the child's own size when it spawned the
  compiler, see :class:`DescendantPeak`); and the compiler's own peak (``VmHWM`` of the
  child's descendants, sampled from /proc during the build; Linux only).

Growth exponents are least-squares slopes of log(value) against log(N) over the sizes that
finished, and the slope between the two largest of them (constant costs flatten the small sizes).
Only public API is used (``daeclear.simulate``, ``daeclear.assemble``,
``daeclear.mechanisms.chain``, ``daeclear.engine.codegen.cache_dir``), so the benchmark keeps working
when the compiled engine changes.

``--write-doc`` writes the table into docs/performance.md (block "scaling"): times as ratios to
N = 1's and growth exponents; steps and events are deterministic (tests/test_doc_numbers.py checks them).

    python benchmarks/bench_scaling.py [--sizes 1,2,4,8,16,32] [--t-end 0.05] [--repeats 3] [--timeout 300]
        [--write-doc]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import platform
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

BUILD_T_END = 1e-4  # s: the build-time calls; the first impact is ~4.5 ms away, so this is set-up only
TAG = "@@bench "  # prefix of the child's JSON report lines on stdout
# Targets of the compiled engine: build time at given sizes, and its growth exponent.
BUILD_TARGETS = {16: 15.0, 32: 45.0}
BUILD_EXPONENT_TARGET = 1.3


# --------------------------------------------------------------------------- child: one size


def _report(**values: Any) -> None:
    """Hand values to the parent at once, so a later timeout does not lose them."""
    print(TAG + json.dumps(values), flush=True)


def _max_rss_mb(who: int) -> float:
    """Peak resident set size in MB (ru_maxrss is in kB on Linux, in bytes on macOS)."""
    rss = resource.getrusage(who).ru_maxrss
    return rss / (1024.0 * 1024.0) if sys.platform == "darwin" else rss / 1024.0


class DescendantPeak:
    """Largest peak RSS (VmHWM) of this process's descendants, sampled from /proc (Linux).

    ``RUSAGE_CHILDREN`` alone cannot give the compiler's memory: Linux charges a child spawned
    from Python with the Python process's own peak until the exec, so that number is never
    below the parent's size. The peak of a process's own image (``VmHWM``, monotonic) is free
    of this; it is sampled every ``interval`` seconds while the compiler runs.
    """

    def __init__(self, interval: float = 0.02) -> None:
        self.interval = interval
        self.peak_kb = 0
        self.available = Path(f"/proc/{os.getpid()}/task").is_dir()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def __enter__(self) -> DescendantPeak:
        if self.available:
            self._thread.start()
        return self

    def __exit__(self, *exc: Any) -> None:
        self._stop.set()
        if self.available:
            self._thread.join()

    @property
    def peak_mb(self) -> float | None:
        return self.peak_kb / 1024.0 if self.available and self.peak_kb else None

    @staticmethod
    def _children(pid: int) -> list[int]:
        out: list[int] = []
        with contextlib.suppress(OSError):
            for task in Path(f"/proc/{pid}/task").iterdir():
                with contextlib.suppress(OSError, ValueError):
                    out += [int(c) for c in (task / "children").read_text().split()]
        return out

    def _sample(self) -> None:
        todo = self._children(os.getpid())
        while todo:
            pid = todo.pop()
            with contextlib.suppress(OSError, ValueError):
                for line in Path(f"/proc/{pid}/status").read_text().splitlines():
                    if line.startswith("VmHWM:"):
                        self.peak_kb = max(self.peak_kb, int(line.split()[1]))
                        break
            todo += self._children(pid)

    def _run(self) -> None:
        while not self._stop.wait(self.interval):
            self._sample()


def child(n: int, t_end: float, repeats: int) -> None:
    """Measure one chain size in this (fresh) process and report as TAG lines on stdout."""
    import daeclear as dc
    from daeclear.engine.codegen import cache_dir

    _report(cache=str(cache_dir()))
    scene = dc.mechanisms.chain(n)
    model = dc.assemble(scene)
    _report(states=model.n_states, constraints=model.n_constraints)

    with DescendantPeak() as compiler:
        start = time.perf_counter()
        first = dc.simulate(scene, BUILD_T_END)
        cold = time.perf_counter() - start
    warm_short = math.inf
    for _ in range(2):
        start = time.perf_counter()
        dc.simulate(scene, BUILD_T_END)
        warm_short = min(warm_short, time.perf_counter() - start)
    compile_time = first.stats.get("compile_time")
    _report(build=max(cold - warm_short, 0.0), compile=compile_time, cc_peak=compiler.peak_mb,
            rss_self=_max_rss_mb(resource.RUSAGE_SELF), rss_children=_max_rss_mb(resource.RUSAGE_CHILDREN))

    best = math.inf
    result = None
    for _ in range(max(repeats, 1)):
        start = time.perf_counter()
        result = dc.simulate(scene, t_end, on_failure="return")
        best = min(best, time.perf_counter() - start)
    assert result is not None
    _report(solve=best / t_end, steps=int(result.stats.get("n_steps", -1)), events=len(result.events),
            success=bool(result.success), message=result.message,
            rss_self=_max_rss_mb(resource.RUSAGE_SELF), rss_children=_max_rss_mb(resource.RUSAGE_CHILDREN))


# --------------------------------------------------------------------------- parent: all sizes


@dataclass
class Row:
    """What was measured for one size; None where the measurement did not get that far."""

    n: int
    values: dict[str, Any] = field(default_factory=dict)
    code_bytes: int | None = None
    status: str = "ok"
    elapsed: float = 0.0

    def get(self, key: str) -> Any:
        return self.values.get(key)


def _code_bytes(root: Path) -> int | None:
    """Bytes of generated C in a fresh cache directory (including a killed build's source)."""
    files = [p for p in root.rglob("*.c") if p.is_file()]
    return sum(p.stat().st_size for p in files) if files else None


def measure(n: int, t_end: float, repeats: int, timeout: float) -> Row:
    """Run one size in a child process with an empty cache; kill its whole process group on timeout."""
    row = Row(n)
    cache = Path(tempfile.mkdtemp(prefix=f"daeclear-bench-n{n}-"))
    env = {**os.environ, "DAECLEAR_CACHE_DIR": str(cache)}
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", str(n), "--t-end", repr(t_end),
           "--repeats", str(repeats)]
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            start_new_session=True)  # own process group: the compiler dies with it
    try:
        out, err = proc.communicate(timeout=timeout)
        if proc.returncode != 0:
            lines = [line for line in err.strip().splitlines() if line.strip()]
            row.status = f"error (exit {proc.returncode}): {lines[-1] if lines else ''}"[:120]
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):  # the group may be gone already
            os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        row.status = "timeout"
    row.elapsed = time.perf_counter() - start
    for line in out.splitlines():
        if line.startswith(TAG):
            row.values.update(json.loads(line[len(TAG):]))
    if row.status == "ok" and row.get("success") is False:
        row.status = f"solve failed: {row.get('message')}"[:120]
    row.code_bytes = _code_bytes(cache)
    shutil.rmtree(cache, ignore_errors=True)
    return row


def growth_exponent(rows: list[Row], value: Any, last: int | None = None) -> tuple[float | None, int]:
    """Least-squares slope of log(value) vs log(N) over the rows with a positive value (only the
    ``last`` largest sizes if given), and the number of sizes fitted."""
    points = sorted((math.log(r.n), math.log(v)) for r in rows if (v := value(r)) is not None and v > 0)
    if last is not None:
        points = points[-last:]
    if len(points) < 2 or len({x for x, _ in points}) < 2:
        return None, len(points)
    mx = sum(x for x, _ in points) / len(points)
    my = sum(y for _, y in points) / len(points)
    sxx = sum((x - mx) ** 2 for x, _ in points)
    sxy = sum((x - mx) * (y - my) for x, y in points)
    return sxy / sxx, len(points)


def _fmt(value: Any, spec: str, missing: str = "-") -> str:
    return missing if value is None else format(value, spec)


def build_target(n: int, build: float | None, timed_out_after: float | None = None) -> str:
    """'< 15 s ok' / '< 15 s MISSED' for sizes with a target, '' otherwise."""
    if n not in BUILD_TARGETS:
        return ""
    limit = BUILD_TARGETS[n]
    if build is None:
        verdict = "MISSED" if timed_out_after is not None and timed_out_after >= limit else "?"
    else:
        verdict = "ok" if build < limit else "MISSED"
    return f"< {limit:g} s {verdict}"


def print_table(rows: list[Row], t_end: float, timeout: float) -> None:
    header = (f"{'N':>3} {'states':>6} {'C code kB':>10} {'build s':>8} {'cc s':>7} {'target':>14} "
              f"{'solve s/s':>10} {'steps':>7} {'events':>6} {'RSS MB':>7} {'kids MB':>7} {'cc MB':>6}  status")
    print(header)
    print("-" * len(header))
    for r in rows:
        build = r.get("build")
        if build is None and r.status == "timeout":
            build_text = f">{timeout:g}"
        else:
            build_text = _fmt(build, ".2f")
        target = build_target(r.n, build, timeout if r.status == "timeout" else None)
        print(f"{r.n:>3} {_fmt(r.get('states'), 'd'):>6} "
              f"{_fmt(None if r.code_bytes is None else r.code_bytes / 1e3, '.1f'):>10} "
              f"{build_text:>8} {_fmt(r.get('compile'), '.2f'):>7} {target:>14} "
              f"{_fmt(r.get('solve'), '.3f'):>10} {_fmt(r.get('steps'), 'd'):>7} {_fmt(r.get('events'), 'd'):>6} "
              f"{_fmt(r.get('rss_self'), '.0f'):>7} {_fmt(r.get('rss_children'), '.0f'):>7} "
              f"{_fmt(r.get('cc_peak'), '.0f'):>6}  {r.status}")
    print()
    print(f"solve: warm simulate(scene, {t_end:g} s) wall time per simulated second, best of the repeats; "
          "RSS: peak of the measuring process;\nkids: RUSAGE_CHILDREN peak (never below the Python process's "
          "size at the compiler's spawn); cc: compiler's own peak (VmHWM sampled from /proc)")
    fits = (("build time", lambda r: r.get("build"), BUILD_EXPONENT_TARGET),
            ("C code size", lambda r: r.code_bytes, None),
            ("solve time", lambda r: r.get("solve"), None))
    for label, value, target in fits:
        slope, count = growth_exponent(rows, value)
        text = "n/a (fewer than two sizes)" if slope is None else f"N^{slope:.2f} over {count} sizes"
        local, _ = growth_exponent(rows, value, last=2)
        if local is not None and count > 2:  # small sizes are dominated by constant costs
            text += f", N^{local:.2f} between the two largest"
        if target is not None:
            verdict = "" if slope is None else (" ok" if slope <= target + 0.05 else " MISSED")
            text += f"   (target <= about N^{target:g}{verdict})"
        print(f"growth of {label:<12}: {text}")
    if any(r.status == "timeout" for r in rows):
        print(f"timed-out sizes (> {timeout:g} s) are left out of the fits: the true growth is steeper.")


def doc_table(rows: list[Row], t_end: float) -> list[str]:
    """The Markdown table of --write-doc: counts, sizes, and times relative to the smallest size's."""
    first = rows[0]

    def ratio(r: Row, key: str) -> str:
        return "-" if r.get(key) is None or not first.get(key) else f"{r.get(key) / first.get(key):.1f}"

    lines = [f"| N | states | C code | build / N = {first.n}'s | solve / N = {first.n}'s | steps | events | RSS | "
             "cc MB |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        code = "-" if r.code_bytes is None else f"{r.code_bytes / 1e3:.0f} kB"
        lines.append(f"| {r.n} | {_fmt(r.get('states'), 'd')} | {code} | {ratio(r, 'build')} | {ratio(r, 'solve')} | "
                     f"{_fmt(r.get('steps'), 'd')} | {_fmt(r.get('events'), 'd')} | "
                     f"{_fmt(r.get('rss_self'), '.0f')} MB | {_fmt(r.get('cc_peak'), '.0f')} |")
    lines.append("")
    growth = []
    for label, value in (("build time", lambda r: r.get("build")), ("C code", lambda r: r.code_bytes),
                         ("solve time", lambda r: r.get("solve"))):
        slope, count = growth_exponent(rows, value)
        local, _ = growth_exponent(rows, value, last=2)
        if slope is not None:
            growth.append(f"{label} N^{slope:.2f}" + (f" (N^{local:.2f} between the two largest)"
                                                       if local is not None and count > 2 else ""))
    lines.append(f"Growth over N = {rows[0].n}-{rows[-1].n}: " + ", ".join(growth) + f"; solve: warm "
                 f"`simulate(scene, {t_end:g} s)`, best of the repeats; build: first call minus a warm one.")
    slope, _ = growth_exponent(rows, lambda r: r.get("build"))
    verdicts = [f"N = {r.n} built within {BUILD_TARGETS[r.n]:g} s: {build_target(r.n, r.get('build')).split()[-1]}"
                for r in rows if r.n in BUILD_TARGETS]
    if slope is not None:
        verdicts.append(f"build time growing no faster than about N^{BUILD_EXPONENT_TARGET:g}: "
                        + ("ok" if slope <= BUILD_EXPONENT_TARGET + 0.05 else "MISSED"))
    if verdicts:
        lines.append("Targets (the compiled engine's issue): " + "; ".join(verdicts) + ".")
    return lines


def _sizes(text: str) -> list[int]:
    try:
        sizes = [int(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--sizes {text!r}: expected integers >= 1, e.g. 1,2,4") from None
    if not sizes or min(sizes) < 1:
        raise argparse.ArgumentTypeError(f"--sizes {text!r}: expected integers >= 1, e.g. 1,2,4")
    return sizes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=_sizes, default=[1, 2, 4, 8, 16, 32],
                        help="chain sizes N (default 1,2,4,8,16,32)")
    parser.add_argument("--t-end", type=float, default=0.05, help="simulated time of the solve measurement, s (0.05)")
    parser.add_argument("--repeats", type=int, default=3, help="warm solve repeats, best kept (3)")
    parser.add_argument("--timeout", type=float, default=300.0, help="wall-time limit per size, s (300)")
    parser.add_argument("--write-doc", action="store_true", help="write the table into docs/performance.md")
    parser.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.t_end <= 0 or args.repeats < 1 or args.timeout <= 0:
        parser.error("--t-end and --timeout must be > 0 and --repeats >= 1")
    if args.child is not None:
        child(args.child, args.t_end, args.repeats)
        return
    import daeclear

    print(f"daeclear {daeclear.__version__}, Python {platform.python_version()}, {platform.platform()}, "
          f"{os.cpu_count()} CPUs; chain of N links, every pin a clearance joint; t_end {args.t_end:g} s, "
          f"timeout {args.timeout:g} s per size")
    rows: list[Row] = []
    for n in args.sizes:
        row = measure(n, args.t_end, args.repeats, args.timeout)
        rows.append(row)
        print(f"  N={n}: {row.status} in {row.elapsed:.1f} s", flush=True)
    print()
    print_table(rows, args.t_end, args.timeout)
    if args.write_doc:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from doc_tables import write_block

        command = "python benchmarks/bench_scaling.py" + ("" if args.sizes == [1, 2, 4, 8, 16, 32] else
                                                          f" --sizes {','.join(map(str, args.sizes))}")
        print(f"wrote {write_block('docs/performance.md', 'scaling', command, doc_table(rows, args.t_end))}")


if __name__ == "__main__":
    main()
