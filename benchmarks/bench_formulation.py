"""Index-1 Baumgarte against GGL (and candidates) at small clearances: accuracy and cost.

    python benchmarks/bench_formulation.py [--revolutions 10] [--repeats 2] [--quick] [--write-doc]

For the chapter's slider-crank (``mechanisms.slider_crank``, gravity on, 5000 rpm) with a
revolute clearance joint of c = 0.5, 0.1, 0.02, 0.01 mm, the ideal mechanism and the
translational clearance joint (c = 0.5 mm), and rtol 1e-6 and 1e-8, every formulation is run as
users call it, ``simulate(scene, ...)`` (a Scene in, assembly and set-up included):

- ``onset``: relative error of the first contact onset time against the reference (GGL at
  rtol 1e-11; cross-checked against DOP853 at rtol 1e-12, which integrates the index-1 ODE with
  every state in the error test);
- ``moment`` and ``accel``: largest error of ``drive.moment`` and ``slider.ax`` on the first
  2 ms (the first impacts; 400 points), relative to the reference's largest magnitude there;
- ``drift``: peak constraint violation |Phi| over --revolutions crank revolutions, m and as a
  fraction of the clearance;
- ``steps``, ``cpu`` and ``wall``: IDA steps, CPU time and wall time (each the best of
  --repeats after a warm-up) of the whole --revolutions run. On a loaded machine compare ``cpu``.

A second table: the free elastic translational slider-crank (no driver, no gravity, restitution 1,
0.05 s from the declared state), where mechanical plus elastic energy is conserved: its relative
change, steps and CPU time per formulation and rtol.

Candidates besides ``index1`` (the chapter's, alpha = beta = 5) and ``ggl``:
``index1 a=b=500`` (Baumgarte scaled to the crank speed, 524 rad/s) and ``index1+proj``
(index-1 with every restart after a contact switch projected onto the constraint manifold, as
GGL restarts are; measured by switching the projection on for index-1 here, not an option).

``--write-doc`` writes the index1 and ggl rows into docs/engine.md (block "formulation"), each run's
CPU time as a ratio to index1's on the same scene and rtol.
"""

from __future__ import annotations

import argparse
import copy
import sys
import time
import warnings
from pathlib import Path
from typing import Any
from collections.abc import Callable

import numpy as np

import daeclear as dc
from daeclear.assembly.assemble import DAEModel

REV = 60.0 / 5000.0
WINDOW = 0.002
RTOLS = (1e-6, 1e-8)
REFERENCE_RTOL = 1e-11


class ProjectedIndex1(DAEModel):
    """index-1 model whose compiled loop projects every restart onto the constraint manifold."""

    def layout(self, project: bool) -> Any:
        return super().layout(True)


def _projected(scene: dc.Scene) -> DAEModel:
    model = copy.copy(dc.assemble(scene, "index1"))  # the assembled model may be shared: a copy
    object.__setattr__(model, "__class__", ProjectedIndex1)  # measurement only, not an option
    return model


CANDIDATES: dict[str, Callable[[dc.Scene], Any]] = {
    "index1": lambda scene: dc.assemble(scene, "index1"),
    "ggl": lambda scene: dc.assemble(scene, "ggl"),
    "index1 a=b=500": lambda scene: dc.assemble(scene, "index1", alpha=500.0, beta=500.0),
    "index1+proj": _projected,
}


def scenes() -> dict[str, tuple[dc.Scene, float]]:
    """Label -> (scene, clearance in m; 0 for the ideal mechanism)."""
    out: dict[str, tuple[dc.Scene, float]] = {}
    for c_mm in (0.5, 0.1, 0.02, 0.01):
        out[f"revolute c={c_mm:g} mm"] = (dc.mechanisms.slider_crank("revolute", clearance=c_mm * 1e-3), c_mm * 1e-3)
    out["ideal"] = (dc.mechanisms.slider_crank("ideal"), 0.0)
    out["translational c=0.5 mm"] = (dc.mechanisms.slider_crank("translational"), 0.5e-3)
    return out


def first_onset(result: dc.Result) -> float:
    onsets = result.events.of(kind="onset").t
    return float(onsets[0]) if onsets.size else float("nan")


def run(make: Callable[[dc.Scene], Any], scene: dc.Scene, t_end: float, repeats: int,
        **kwargs: Any) -> tuple[dc.Result, float, float]:
    """Whole calls (the model made from the Scene, as simulate does, and the run): the result and
    the best CPU and wall times of ``repeats`` calls after a warm-up."""
    cpu, wall = [], []
    for _ in range(repeats + 1):
        tic, tic_cpu = time.perf_counter(), time.process_time()
        result = dc.simulate(make(scene), t_end, **kwargs)
        cpu.append(time.process_time() - tic_cpu)
        wall.append(time.perf_counter() - tic)
    return result, min(cpu[1:]), min(wall[1:])


def free_translational() -> dc.Scene:
    scene = dc.mechanisms.slider_crank("translational", gravity=0.0, restitution=1.0)
    scene.elements = [e for e in scene.elements if not isinstance(e, dc.Driver)]
    return scene


def energy_table(repeats: int) -> list[str]:
    """The free slider-crank's energy table (printed), and its rows with CPU time as a ratio to index1's."""
    print("\nfree elastic translational slider-crank, 0.05 s: energy conservation")
    print("| formulation | rtol | energy change / E0 | steps | cpu (s) |")
    print("|---|---|---|---|---|")
    scene = free_translational()
    doc = ["| free elastic translational slider-crank, 0.05 s | rtol | energy change / E0 | steps | CPU / index1's |",
           "|---|---|---|---|---|"]
    index1_cpu: dict[float, float] = {}
    for name in ("index1", "ggl"):
        for rtol in (1e-8, 1e-9):
            result, cpu, _ = run(CANDIDATES[name], scene, 0.05, repeats, rtol=rtol,
                                 options=dc.SolverOptions(start="declared"))
            total = result["energy.mechanical"] + result["clearance.elastic_energy"]
            print(f"| {name} | {rtol:.0e} | {np.ptp(total) / total[0]:.1e} | {result.stats['n_steps']} | {cpu:.3f} |",
                  flush=True)
            index1_cpu.setdefault(rtol, cpu)
            doc.append(f"| {name} | {rtol:.0e} | {np.ptp(total) / total[0]:.1e} | {result.stats['n_steps']} | "
                       f"{cpu / index1_cpu[rtol]:.2f} |")
    return doc


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--revolutions", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="only c = 0.5 and 0.01 mm, index1 and ggl")
    parser.add_argument("--write-doc", action="store_true", help="write the index1 and ggl rows into docs/engine.md")
    args = parser.parse_args()
    warnings.simplefilter("ignore", dc.DaeclearWarning)
    t_long = args.revolutions * REV
    grid = np.linspace(0.0, WINDOW, 401)
    candidates = {k: v for k, v in CANDIDATES.items() if not args.quick or k in ("index1", "ggl")}
    print(f"slider-crank, 5000 rpm, gravity on; window {WINDOW * 1e3:g} ms for onset/moment/accel, "
          f"{args.revolutions} revolutions for drift/steps/wall (best of {args.repeats})")
    print("| scene | formulation | rtol | onset rel. err | moment err | accel err | drift (m) | drift / c | steps "
          "| cpu (s) | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    doc = ["| scene | formulation | rtol | onset err | moment err | drift (m) | drift / c | steps | CPU / index1's |",
           "|---|---|---|---|---|---|---|---|---|"]
    for label, (scene, clearance) in scenes().items():
        if args.quick and label not in ("revolute c=0.5 mm", "revolute c=0.01 mm"):
            continue
        ref = dc.simulate(scene, WINDOW, rtol=REFERENCE_RTOL, options=dc.SolverOptions(formulation="ggl"),
                          save=dc.SaveAt(times=grid))
        ref_onset = first_onset(ref)
        note = ""
        if clearance and label.startswith("revolute"):
            dop = dc.simulate(scene, WINDOW, rtol=1e-12, method="DOP853")
            note = f" (DOP853 rtol 1e-12 onset differs by {abs(first_onset(dop) - ref_onset) / ref_onset:.1e})"
        scale = {ch: float(np.max(np.abs(ref[ch]))) for ch in ("drive.moment", "slider.ax")}
        index1_cpu: dict[float, float] = {}
        for name, make in candidates.items():
            for rtol in RTOLS:
                short = dc.simulate(make(scene), WINDOW, rtol=rtol, save=dc.SaveAt(times=grid))
                onset = abs(first_onset(short) - ref_onset) / ref_onset if clearance else float("nan")
                err = {ch: float(np.max(np.abs(short[ch] - ref[ch]))) / scale[ch] for ch in scale}
                long, cpu, wall = run(make, scene, t_long, args.repeats, rtol=rtol)
                drift = long.stats["max_constraint_drift"]
                frac = f"{drift / clearance:.1e}" if clearance else ""
                print(f"| {label} | {name} | {rtol:.0e} | {onset:.1e} | {err['drive.moment']:.1e} | "
                      f"{err['slider.ax']:.1e} | {drift:.1e} | {frac} | {long.stats['n_steps']} | "
                      f"{cpu:.3f} | {wall:.3f} |", flush=True)
                if name == "index1":
                    index1_cpu[rtol] = cpu
                if name in ("index1", "ggl"):
                    first = name == "index1" and rtol == RTOLS[0]
                    doc.append(f"| {label if first else ''} | {name} | {rtol:.0e} | "
                               f"{'' if not clearance else f'{onset:.1e}'} | {err['drive.moment']:.1e} | {drift:.1e} | "
                               f"{frac} | {long.stats['n_steps']} | {cpu / index1_cpu[rtol]:.2f} |")
        if note:
            print(f"|  | reference: GGL rtol {REFERENCE_RTOL:.0e}{note} | | | | | | | | | |", flush=True)
    energy = energy_table(args.repeats) if not args.quick else []
    if args.write_doc:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from doc_tables import write_block

        doc += ["", f"{args.revolutions} revolutions for drift, steps and CPU time (best of {args.repeats}); onset "
                f"and moment errors over the first {WINDOW * 1e3:g} ms against GGL at rtol {REFERENCE_RTOL:g}."]
        if energy:
            doc += ["", *energy]
        command = "python benchmarks/bench_formulation.py" + (" --quick" if args.quick else "")
        print(f"wrote {write_block('docs/engine.md', 'formulation', command, doc)}")


if __name__ == "__main__":
    main()
