"""Sensitivities through impacts: gradients of the peak crank moment and the predictability horizon.

The chapter's slider-crank with a revolute clearance joint (Fig. 4.15's scene: c = 0.5 mm, Lankarani-Nikravesh,
5000 rpm): d(peak crank moment in the first 0.7 ms)/d p from forward sensitivities through every impact,
against central differences of separate runs, for five parameters in three variants of the joint:

* dry, with modified Coulomb friction mu = 0.05: the clearance, the restitution and the friction coefficient;
* lubricated (``HydrodynamicBearing``, 0.1 Pa s, 10 mm long, short bearing): the oil's viscosity;
* dry with friction, its bearing worn 20 um (1 + cos theta) deep (``ArchardWear``, 36 nodes, 4 modes): the
  worn profile's first cosine mode ``clearance.wear.bearing_cos[1]``, in m.

Then the growth of the sensitivities over the first revolution at c = 0.5 and 0.1 mm, with their finite-time
Lyapunov estimate and predictability horizon (``result.sensitivity_horizon``, drawn by
``plot_sensitivity_horizon(result)``).

Writes into ``--out`` (default ``results/sensitivity_study/``): ``gradients.json`` (each variant's peak, its
gradients by both methods and the relative ones d ln(peak)/d ln p, each clearance's horizon) and
``sensitivity_horizon.png`` (the relative gradients, then the two horizons). Run:
``python examples/sensitivity_study.py`` (``--quick``: 0.4 ms and 2 ms).
"""

from __future__ import annotations

import argparse
import json
import warnings
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402
from daeclear.assembly.sensitivity import parameter_value  # noqa: E402
from daeclear.contact import HydrodynamicBearing  # noqa: E402
from daeclear.contact.wear import ArchardWear  # noqa: E402
from daeclear.plot import plot_sensitivity_horizon  # noqa: E402

PARAMETERS = ["clearance.clearance", "clearance.law.restitution"]  # the horizon runs'
RTOL = 1e-10
FRICTION = 0.05
WEAR_NODES = 36
WEAR_DEPTH = 20e-6  # m: the worn profile 20 um (1 + cos theta), its first cosine mode 20 um


def variants() -> dict[str, tuple[dc.Scene, list[str]]]:
    """Each variant's scene and the parameters its gradient is taken to."""
    dry = dc.mechanisms.slider_crank("revolute", friction=FRICTION)
    theta = 2 * np.pi * np.arange(WEAR_NODES) / WEAR_NODES
    worn = dry.with_values({"clearance.wear": ArchardWear(coefficient=1e-13, length=0.02, nodes=WEAR_NODES, modes=4),
                            "clearance.wear_depth": WEAR_DEPTH * (1.0 + np.cos(theta))})
    oil = dc.mechanisms.slider_crank("revolute", law=HydrodynamicBearing(viscosity=0.1, length=10e-3))
    return {"dry, friction 0.05": (dry, ["clearance.clearance", "clearance.law.restitution",
                                         "clearance.friction.coefficient"]),
            "lubricated": (oil, ["clearance.law.viscosity"]),
            "worn bearing": (worn, ["clearance.wear.bearing_cos[1]"])}


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short spans (a smoke run)")
    parser.add_argument("--out", type=Path, default=Path("results/sensitivity_study"))
    return parser.parse_args(argv)


def gradients(span: float) -> dict[str, dict[str, Any]]:
    """Each variant's peak crank moment and its gradient by sensitivities and by central differences, with the
    relative gradient d ln(peak)/d ln p (which parameter matters most) and the run's contact events."""
    of = dc.Peak("drive.moment", absolute=True)
    out: dict[str, dict[str, Any]] = {}
    for label, (scene, parameters) in variants().items():
        model = dc.assemble(scene)
        entry: dict[str, Any] = {}
        for method in ("sensitivities", "fd"):
            g = dc.gradient(model, span, of=of, parameters=parameters, rtol=RTOL, method=method, samples=400)
            entry[method] = {"peak crank moment (N m)": g.value, **g.gradient}
            print(f"{label:>18}, {method:>13}: peak {g.value:.6g} N m, "
                  + ", ".join(f"d/d {k} = {v:.6g}" for k, v in g.gradient.items()))
        values = {name: parameter_value(model, name) for name in parameters}
        entry["values"] = values
        entry["relative"] = {name: entry["sensitivities"][name] * values[name] / entry["sensitivities"][
            "peak crank moment (N m)"] for name in parameters}
        run = dc.simulate(model, span, rtol=1e-8, save=dc.SaveAt(times=[0.0, span], steps=False))
        entry["events"] = dict(Counter(e.kind for e in run.events))
        out[label] = entry
    return out


def plot_relative(ax: Any, grads: dict[str, dict[str, Any]], span: float) -> None:
    """d ln(peak)/d ln p of every parameter, by sensitivities and by central differences side by side."""
    labels, sens, fd = [], [], []
    for entry in grads.values():
        peak = entry["sensitivities"]["peak crank moment (N m)"]
        for name, value in entry["values"].items():
            labels.append(name.removeprefix("clearance."))
            sens.append(entry["sensitivities"][name] * value / peak)
            fd.append(entry["fd"][name] * value / entry["fd"]["peak crank moment (N m)"])
    rows = np.arange(len(labels))
    ax.barh(rows - 0.2, sens, height=0.4, label="sensitivities")
    ax.barh(rows + 0.2, fd, height=0.4, label="central differences")
    ax.set_yticks(rows, labels)
    ax.axvline(0.0, color="k", lw=0.5)
    ax.set_xlabel("d ln(peak crank moment) / d ln p")
    ax.set_title(f"peak crank moment in the first {span * 1e3:g} ms")
    ax.legend(fontsize=8)


def horizon_run(clearance: float, span: float) -> dc.Result:
    """A run over ``span`` with the sensitivities to the clearance and the restitution, at rtol 1e-8: its
    ``sensitivity_horizon`` is their growth, Lyapunov estimate and predictability horizon."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=clearance))
    run = dc.simulate(model, span, rtol=1e-8, save=dc.SaveAt(times=np.linspace(0.0, span, 201), steps=False),
                      sensitivities=PARAMETERS, on_failure="return")
    h = run.sensitivity_horizon
    print(f"c = {clearance * 1e3:g} mm: lambda = {h.lyapunov:.3g} 1/s, horizon {h.horizon * 1e3:.3g} ms "
          f"({'past' if h.predictable else 'within'} the run's {span * 1e3:g} ms)")
    return run


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    # 0.7 ms: two impacts, before the friction's first slip reversal (0.7255 ms), through which IDA cannot carry
    # S in its error test (docs/sensitivities.md, section 7)
    span = 0.4e-3 if args.quick else 0.7e-3
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result: dict[str, Any] = {"span (s)": span, "gradients": gradients(span)}
        fig, axes = plt.subplots(1, 3, figsize=(16, 4), gridspec_kw={"width_ratios": [1.2, 1, 1]})
        plot_relative(axes[0], result["gradients"], span)
        result["horizons"] = {}
        for ax, clearance in zip(axes[1:], (0.5e-3, 0.1e-3)):
            run = horizon_run(clearance, 2e-3 if args.quick else 12e-3)
            plot_sensitivity_horizon(run, ax=ax, label=f"c = {clearance * 1e3:g} mm")
            h = run.sensitivity_horizon
            result["horizons"][f"{clearance * 1e3:g} mm"] = {"lyapunov (1/s)": h.lyapunov, "horizon (s)": h.horizon,
                                                             "predictable": h.predictable}
        axes[2].sharey(axes[1])
    path = args.out / "sensitivity_horizon.png"
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    (args.out / "gradients.json").write_text(json.dumps(result, indent=2))
    print(f"wrote {path} and {args.out / 'gradients.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
