"""Memory of a run against its length: peak RSS and tracemalloc peak per simulated crank revolution.

    python benchmarks/bench_memory.py [--revolutions 2,8] [--rpm 5000] [--configs all]

The chapter's slider-crank with a revolute clearance joint (0.5 mm, rtol 1e-6) is run for each
number of revolutions in ``--revolutions`` with each output configuration, every run in a fresh
subprocess (so peak RSS is that run's alone, after the model is compiled once in a warm-up):

``steps``        every IDA step reported and kept (the API default without ``t_eval``)
``grid``         reported points every 1e-5 s (``t_eval_step``), IDA steps' times kept
``grid-nosteps`` as ``grid`` with ``store_steps=False``
``stream``       as ``grid-nosteps``, streamed to an HDF5 file (``stream_to``), nothing returned
``cli``          ``daeclear run slider_crank --joint revolute`` (its own defaults), in a subprocess

For each it prints the tracemalloc peak (Python and numpy allocations) and the peak RSS, their
growth per revolution between the shortest and the longest run, and the number of output
points. Memory that does not grow with the run is the goal of ``stream`` and ``cli``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONFIGS = ("steps", "grid", "grid-nosteps", "stream", "cli")
GRID = 1e-5  # s, the reported points of the grid configurations


def _points(path: Path) -> int:
    """Output points of a result file, read without loading it."""
    import h5py

    with h5py.File(path, "r") as f:
        return int(f["t"].shape[0])


def child(config: str, revolutions: int, rpm: float) -> dict:
    """One run in this process; returns its figures (JSON-able)."""
    import tracemalloc
    import warnings

    import daeclear as dc

    warnings.simplefilter("ignore")
    t_end = revolutions * 60.0 / rpm
    scene = dc.mechanisms.slider_crank("revolute", rpm=rpm)
    dc.simulate(scene, 60.0 / rpm / 8, rtol=1e-6)  # compile (or load) the model before measuring
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with tempfile.TemporaryDirectory() as tmp:
        tracemalloc.start()
        if config == "cli":
            from daeclear.cli import main

            code = main(["run", "slider_crank", "--joint", "revolute", "--set", f"rpm={rpm}", "--t-end", str(t_end),
                         "--out", tmp, "--no-figure", "--quiet"])
            _, peak = tracemalloc.get_traced_memory()
            tracemalloc.stop()
            rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
            n_times = _points(Path(tmp) / "slider_crank_revolute.h5") if code == 0 else -1
        else:
            kwargs: dict = {}
            if config != "steps":
                kwargs["every"] = GRID
            if config in ("grid-nosteps", "stream"):
                kwargs["steps"] = False
            if config == "stream":
                kwargs["stream_to"] = Path(tmp) / "run.h5"
                kwargs["keep_data"] = False
            result = dc.simulate(scene, t_end, rtol=1e-6, save=dc.SaveAt(**kwargs))
            _, peak = tracemalloc.get_traced_memory()
            tracemalloc.stop()
            rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
            n_times = result.n_times if config != "stream" else _points(kwargs["stream_to"])
            del result
    return {"config": config, "revolutions": revolutions, "tracemalloc_peak_mb": peak / 1e6,
            "rss_peak_mb": rss / 1e3, "rss_growth_mb": (rss - rss0) / 1e3, "n_times": n_times}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--revolutions", default="2,8", help="comma-separated run lengths (crank revolutions)")
    parser.add_argument("--rpm", type=float, default=5000.0)
    parser.add_argument("--configs", default="all", help=f"comma-separated, from {', '.join(CONFIGS)}")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        config, revs = args.child.split(":")
        print(json.dumps(child(config, int(revs), args.rpm)))
        return
    configs = CONFIGS if args.configs == "all" else tuple(c.strip() for c in args.configs.split(","))
    revolutions = [int(r) for r in args.revolutions.split(",")]
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    rows: dict[str, list[dict]] = {}
    for config in configs:
        for revs in revolutions:
            out = subprocess.run([sys.executable, __file__, "--child", f"{config}:{revs}", "--rpm", str(args.rpm)],
                                 capture_output=True, text=True, env=env)
            if out.returncode != 0:
                print(f"{config} {revs}: failed\n{out.stderr[-2000:]}", file=sys.stderr)
                continue
            rows.setdefault(config, []).append(json.loads(out.stdout.strip().splitlines()[-1]))
    print(f"slider-crank, revolute clearance, {args.rpm:g} rpm, rtol 1e-6; grid configurations every {GRID:g} s")
    print(f"{'config':<14}{'revs':>5}{'points':>10}{'tracemalloc MB':>16}{'RSS growth MB':>15}{'RSS peak MB':>13}")
    for config, found in rows.items():
        for r in found:
            print(f"{config:<14}{r['revolutions']:>5}{r['n_times']:>10}{r['tracemalloc_peak_mb']:>16.2f}"
                  f"{r['rss_growth_mb']:>15.1f}{r['rss_peak_mb']:>13.1f}")
        if len(found) >= 2:
            a, b = found[0], found[-1]
            d = b["revolutions"] - a["revolutions"]
            print(f"{'':<14}per revolution: tracemalloc "
                  f"{(b['tracemalloc_peak_mb'] - a['tracemalloc_peak_mb']) / d:.3f} MB, RSS "
                  f"{(b['rss_growth_mb'] - a['rss_growth_mb']) / d:.3f} MB")


if __name__ == "__main__":
    main()
