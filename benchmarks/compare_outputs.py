"""Two trees of the package, the same example scripts: are the HDF5 files they write equal, value for value?

    python benchmarks/compare_outputs.py OLD NEW [--examples revolute_fig4_15 ...] [--rtol 1e-10]

OLD and NEW are two checkouts (e.g. ``git worktree add /tmp/base <rev>`` and this one). Every example
script of NEW's ``examples/`` that takes ``--quick`` (or those named) runs with it in each tree's own package and its
own copy of the script, each in a fresh working folder (``--out`` into it where the script takes one) with
its own fresh compile cache.
Then every ``.h5`` file both wrote is read back by each tree's own ``daeclear.load`` (in its own
interpreter: a result's t, y, yp, every channel, events, segments and steps, whether the file stored
the channels or the reader computes them) or, for other files (sweeps), dataset by dataset, and the
two are compared with ``numpy.array_equal`` (NaN equal to NaN). Values must be equal; run metadata
(``stats``: timings; ``parameters``: the run's settings as written, whose spelling may change with
the API; warnings) is listed apart. Exit status 1 when a value differs or a file is missing in one tree.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

#: the parts of a result file that describe a run rather than hold its values
METADATA = ("stats", "parameters", "warnings_json", "stats_json", "parameters_json")


#: run in each tree's interpreter: every .h5 file below a folder as arrays, into an .npz beside it
READER = r"""
import sys, json
from pathlib import Path
import h5py, numpy as np
import daeclear as dc
for path in sorted(Path(sys.argv[1]).rglob("*.h5")):
    out = {}
    try:
        r = dc.load(path)
    except Exception:
        with h5py.File(path, "r") as f:
            f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
    else:
        out.update(t=r.t, y=r.y, yp=r.yp, stats=json.dumps(r.stats, sort_keys=True),
                   parameters=json.dumps(r.parameters, sort_keys=True), warnings_json=json.dumps(r.warnings))
        out.update({f"channels/{name}": r[name] for name in r.channel_names})
        ev = r.events
        out.update({"events/t": ev.t, "events/pair": np.array(ev.pair, dtype=str),
                    "events/kind": np.array(ev.kind, dtype=str), "events/approach_speed": ev.approach_speed,
                    "segments": json.dumps(r.segments)})
        if r.step_t is not None:
            out.update({"steps/t": r.step_t, "steps/h": r.step_h, "steps/order": r.step_order})
    np.savez(str(path) + ".npz", **{k: np.asarray(v) for k, v in out.items()})
"""


def datasets(path: Path) -> dict[str, np.ndarray]:
    """The arrays its own tree read from an HDF5 file (READER's .npz beside it)."""
    with np.load(str(path) + ".npz", allow_pickle=False) as f:
        return {name: f[name] for name in f.files}


def json_differences(a: str, b: str, at: str = "") -> list[str]:
    """The key paths where two JSON texts differ (to explain a metadata difference)."""
    x, y = (json.loads(a), json.loads(b)) if not at else (a, b)
    if isinstance(x, dict) and isinstance(y, dict):
        return [d for k in sorted(set(x) | set(y)) for d in (
            json_differences(x.get(k), y.get(k), f"{at}.{k}") if k in x and k in y else [f"{at}.{k}"])]
    return [] if x == y else [f"{at or '.'}: {x!r} -> {y!r}"[:160]]


def relative_difference(a: np.ndarray, b: np.ndarray) -> float:
    """max |b - a| / max |a| of two float arrays of one shape (NaN where both are NaN counts as equal; 0 for
    equal arrays, inf when only one is NaN or the scale is 0 and they differ)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    both_nan = np.isnan(a) & np.isnan(b)
    if np.any(np.isnan(a) != np.isnan(b)):
        return float("inf")
    diff = np.where(both_nan, 0.0, np.abs(b - a))
    worst = float(diff.max()) if diff.size else 0.0
    scale = float(np.nanmax(np.abs(a))) if a.size and not np.all(np.isnan(a)) else 0.0
    return 0.0 if worst == 0.0 else (worst / scale if scale > 0 else float("inf"))


def equal(a: np.ndarray, b: np.ndarray, rtol: float = 0.0) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind in "fc" and b.dtype.kind in "fc":
        if a.shape != b.shape:
            return False
        return bool(np.array_equal(a, b, equal_nan=True)) or relative_difference(a, b) <= rtol
    return a.shape == b.shape and bool(np.array_equal(a, b))


def takes_quick(tree: Path, script: Path) -> bool:
    """Whether the example script of ``tree`` lists ``--quick`` in its help (the others write figures or
    animations only)."""
    env = {**os.environ, "PYTHONPATH": f"{tree}{os.pathsep}{tree / 'examples'}", "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, str(script), "--help"], env=env, capture_output=True, text=True,
                          check=False)
    return "--quick" in done.stdout


def run_example(tree: Path, script: Path, folder: Path, cache: Path) -> bool:
    """``script`` of ``tree`` with --quick in ``folder`` (its --out there), libraries built into ``cache``;
    whether it exited 0."""
    args = [sys.executable, str(tree / "examples" / script.name), "--quick"]
    if '"--out"' in script.read_text():
        args += ["--out", str(folder / "out")]
    env = {**os.environ, "PYTHONPATH": f"{tree}{os.pathsep}{tree / 'examples'}", "MPLBACKEND": "Agg",
           "DAECLEAR_CACHE_DIR": str(cache)}
    done = subprocess.run(args, cwd=folder, env=env, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        print(f"  {tree.name}: {script.name} exited {done.returncode}: {done.stderr.strip()[-300:]}")
    read = subprocess.run([sys.executable, "-c", READER, str(folder)], env=env, capture_output=True, text=True,
                          check=False)
    if read.returncode != 0:
        print(f"  {tree.name}: reading {folder} failed: {read.stderr.strip()[-300:]}")
    return done.returncode == 0 and read.returncode == 0


def compare(old: Path, new: Path, rtol: float = 0.0) -> tuple[int, list[str], list[str], tuple[float, str]]:
    """(datasets compared, values that differ, metadata that differ, the largest relative difference of a
    numeric value and where) of the .h5 files both folders hold; ``rtol`` > 0: the tolerance mode (module
    docstring)."""
    n, values, meta = 0, [], []
    worst = (0.0, "")
    files = sorted({p.relative_to(old) for p in old.rglob("*.h5")} | {p.relative_to(new) for p in new.rglob("*.h5")})
    for rel in files:
        if not (old / rel).is_file() or not (new / rel).is_file():
            values.append(f"{rel}: written by one tree only")
            continue
        a, b = datasets(old / rel), datasets(new / rel)
        for name in sorted(set(a) | set(b)):
            n += 1
            is_meta = name.split("/")[-1] in METADATA or any(part in METADATA for part in name.split("/"))
            if rtol > 0 and name.startswith("steps/") and name in a and name in b and a[name].shape != b[name].shape:
                meta.append(f"{rel}:{name} ({a[name].shape[0]} -> {b[name].shape[0]} integrator steps)")
                continue
            if (rtol > 0 and not is_meta and name in a and name in b and a[name].shape == b[name].shape
                    and a[name].dtype.kind in "fc" and b[name].dtype.kind in "fc"):
                d = relative_difference(a[name], b[name])
                if d > worst[0]:
                    worst = (d, f"{rel}:{name}")
            if name not in a or name not in b or not equal(a[name], b[name], rtol):
                what = f"{rel}:{name}"
                if is_meta and name == "parameters" and name in a and name in b:
                    what += " (" + "; ".join(json_differences(str(a[name]), str(b[name]))[:4]) + ")"
                (meta if is_meta else values).append(what)
    return n, values, meta, worst


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--examples", nargs="+", help="script names without .py (default: every example)")
    parser.add_argument("--rtol", type=float, default=0.0,
                        help="tolerance mode: numeric values agree within rtol of their largest magnitude (0: equal)")
    args = parser.parse_args()
    if not args.rtol >= 0:
        parser.error(f"--rtol={args.rtol!r}, must be a number >= 0")
    old, new = args.old.resolve(), args.new.resolve()
    names = args.examples or sorted(p.stem for p in (new / "examples").glob("*.py")
                                    if not p.stem.startswith("_") and not p.stem.endswith("_common"))
    failed = False
    with tempfile.TemporaryDirectory() as tmp, tempfile.TemporaryDirectory() as cache:
        caches = {old: Path(cache) / "old", new: Path(cache) / "new"}  # each tree builds its own libraries
        for name in names:
            script = new / "examples" / f"{name}.py"
            if not (old / "examples" / script.name).is_file():
                print(f"{name}: not in {old} (an example of the new tree alone)")
                continue
            if not takes_quick(new, script):
                print(f"{name}: skipped (takes no --quick: a figure or animation only)")
                continue
            folders = {tree: Path(tmp) / f"{label}-{name}" for label, tree in (("old", old), ("new", new))}
            ran = True
            for tree, folder in folders.items():
                folder.mkdir()
                ran = run_example(tree, script, folder, caches[tree]) and ran
            n, values, meta, worst = compare(folders[old], folders[new], args.rtol)
            verdict = "equal" if not values else f"{len(values)} DIFFER"
            print(f"{name}: {n} datasets in {len(list(folders[new].rglob('*.h5')))} files: values {verdict}"
                  + (f"; metadata differs: {len(meta)}" if meta else "") + ("" if ran else " (a run failed)"))
            for item in values[:20]:
                print(f"    value: {item}")
            for item in meta[:5]:
                print(f"    metadata: {item}")
            if args.rtol > 0:
                print(f"    largest relative difference: {worst[0]:.2e}" + (f" ({worst[1]})" if worst[1] else ""))
            failed = failed or bool(values) or not ran
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
