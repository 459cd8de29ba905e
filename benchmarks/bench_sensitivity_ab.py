"""Runs with sensitivities of this checkout against another checkout's (a branch, main), side by side in one
process: what a change to the sensitivity path gains, as a ratio on a shared machine.

    python benchmarks/bench_sensitivity_ab.py --other /path/to/other/checkout [--repeats 9] [--times 20]
        [--rtol 1e-6] [--fresh-starts] [--cases slider-crank chain]

The other checkout's package is copied into a temporary directory as ``daeclear_other`` (its imports are
relative) and imported beside this one; both compile into the same cache. For each case of
``bench_sensitivity.CASES`` and Ns = 1 and 5 (its first parameters), each package runs one untimed call,
then ``--repeats`` whole ``simulate`` calls each, alternating which goes first. Printed: the medians, this
checkout's over the other's, the steps of each, and how far apart their S is at every output row (0 where
the change leaves the numbers alone; the NaN rows of a grazing event compared as NaN). ``--fresh-starts``:
the structure's kept starts dropped before every call (a call with new parameter values).
"""

from __future__ import annotations

import argparse
import importlib
import shutil
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

import bench_sensitivity
import daeclear


def other_package(checkout: Path, into: Path) -> ModuleType:
    """The package of ``checkout`` imported as ``daeclear_other`` from a copy in ``into``."""
    source = checkout / "daeclear"
    if not (source / "__init__.py").is_file():
        raise SystemExit(f"bench_sensitivity_ab: --other={checkout}, must be a checkout with daeclear/__init__.py")
    shutil.copytree(source, into / "daeclear_other", ignore=shutil.ignore_patterns("__pycache__"))
    sys.path.insert(0, str(into))
    return importlib.import_module("daeclear_other")


def run(dc: Any, scene: Any, t_end: float, rtol: float, names: list[str], times: int, fresh: bool) -> tuple[Any, float]:
    """One whole simulate call of package ``dc`` and its wall time."""
    save = dc.SaveAt(times=np.linspace(0.0, t_end, times), steps=False) if times else dc.SaveAt()
    if fresh:
        dc.assemble(scene).structure.starts.clear()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        result = dc.simulate(scene, t_end, rtol=rtol, save=save, sensitivities=names)
        return result, time.perf_counter() - start


def compare(case: str, other: ModuleType, width: int, repeats: int, rtol: float, times: int, fresh: bool) -> None:
    """One case and width: medians, ratio, steps and the difference of S."""
    make, t_end, names = bench_sensitivity.CASES[case]
    packages = {"this": daeclear, "other": other}
    scenes = {label: make() if dc is daeclear else _scene(dc, case) for label, dc in packages.items()}
    first = {label: run(dc, scenes[label], t_end, rtol, names[:width], times, fresh)[0]
             for label, dc in packages.items()}
    walls: dict[str, list[float]] = {label: [] for label in packages}
    for r in range(repeats):
        for label in (("this", "other") if r % 2 == 0 else ("other", "this")):
            walls[label].append(run(packages[label], scenes[label], t_end, rtol, names[:width], times, fresh)[1])
    S = {label: np.stack([res.sensitivity(name) for name in res.state_names]).reshape(
        len(res.state_names), res.t.size, -1) for label, res in first.items()}
    nan_alike = np.array_equal(np.isnan(S["this"]), np.isnan(S["other"]))
    diff = float(np.nanmax(np.abs(S["this"] - S["other"])) / np.nanmax(np.abs(S["other"])))
    this, that = statistics.median(walls["this"]), statistics.median(walls["other"])
    print(f"{case:<13} Ns={width}  this {this * 1e3:8.1f} ms  other {that * 1e3:8.1f} ms  "
          f"this/other {this / that:6.3f}  "
          f"steps {first['this'].stats['n_steps']}/{first['other'].stats['n_steps']}  S apart {diff:.1e} "
          f"(NaN alike: {nan_alike}, NaN rows {float(np.isnan(S['this']).any(axis=(0, 2)).mean()):.2f})")


def _scene(dc: Any, case: str) -> Any:
    """The case's scene made by another package (bench_sensitivity's factories use this one's)."""
    if case == "slider-crank":
        return dc.mechanisms.slider_crank("revolute")
    return dc.mechanisms.chain(10, rpm=300.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--other", type=Path, required=True, help="the other checkout (its daeclear/ package)")
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--times", type=int, default=20)
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--fresh-starts", action="store_true")
    parser.add_argument("--cases", nargs="+", choices=sorted(bench_sensitivity.CASES),
                        default=list(bench_sensitivity.CASES))
    args = parser.parse_args()
    if args.repeats < 1 or args.times == 1 or args.times < 0:
        parser.error("--repeats must be at least 1 and --times 0 (every step) or at least 2")
    with tempfile.TemporaryDirectory() as into:
        other = other_package(args.other, Path(into))
        starts = ", fresh starts" if args.fresh_starts else ""
        print(f"this checkout against {args.other}: rtol {args.rtol:g}, {args.times or 'every step'} output times"
              f"{starts}, {args.repeats} calls each, medians (shared machine: ratios only)")
        for case in args.cases:
            for width in (1, 5):
                compare(case, other, width, args.repeats, args.rtol, args.times, args.fresh_starts)


if __name__ == "__main__":
    main()
