"""Sensitivities through impacts: gradients of the peak crank moment and the predictability horizon.

The chapter's slider-crank with a revolute clearance joint (Fig. 4.15's scene: c = 0.5 mm, Lankarani-Nikravesh,
5000 rpm): d(peak crank moment in the first millisecond)/d(clearance, restitution) from forward sensitivities
through every impact, against central differences of separate runs; then the growth of the sensitivities over
the first revolution at c = 0.5 and 0.1 mm, with their finite-time Lyapunov estimate and predictability horizon
(``result.sensitivity_horizon``, drawn by ``plot_sensitivity_horizon(result)``).

Writes into ``--out`` (default ``results/sensitivity_study/``): ``gradients.json`` (the gradients and each
clearance's horizon) and ``sensitivity_horizon.png``. Run: ``python examples/sensitivity_study.py``
(``--quick``: 0.4 ms and 2 ms).
"""

from __future__ import annotations

import argparse
import json
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402
from daeclear.plot import plot_sensitivity_horizon  # noqa: E402

PARAMETERS = ["clearance.clearance", "clearance.law.restitution"]
RTOL = 1e-10


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short spans (a smoke run)")
    parser.add_argument("--out", type=Path, default=Path("results/sensitivity_study"))
    return parser.parse_args(argv)


def gradients(span: float) -> dict[str, dict[str, float]]:
    """The peak crank moment's gradient by sensitivities and by central differences."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute"))
    of = dc.Peak("drive.moment", absolute=True)
    out = {}
    for method in ("sensitivities", "fd"):
        g = dc.gradient(model, span, of=of, parameters=PARAMETERS, rtol=RTOL, method=method, samples=400)
        out[method] = {"peak crank moment (N m)": g.value, **g.gradient}
        print(f"{method:>13}: peak {g.value:.6g} N m, "
              + ", ".join(f"d/d {k} = {v:.6g}" for k, v in g.gradient.items()))
    return out


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
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result: dict[str, Any] = {"gradients": gradients(0.4e-3 if args.quick else 1e-3)}
        fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
        result["horizons"] = {}
        for ax, clearance in zip(axes, (0.5e-3, 0.1e-3)):
            run = horizon_run(clearance, 2e-3 if args.quick else 12e-3)
            plot_sensitivity_horizon(run, ax=ax, label=f"c = {clearance * 1e3:g} mm")
            h = run.sensitivity_horizon
            result["horizons"][f"{clearance * 1e3:g} mm"] = {"lyapunov (1/s)": h.lyapunov, "horizon (s)": h.horizon,
                                                             "predictable": h.predictable}
    path = args.out / "sensitivity_horizon.png"
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    (args.out / "gradients.json").write_text(json.dumps(result, indent=2))
    print(f"wrote {path} and {args.out / 'gradients.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
