"""Sensitivities through impacts: gradients of the peak crank moment and the predictability horizon.

The chapter's slider-crank with a revolute clearance joint (Fig. 4.15's scene: c = 0.5 mm, Lankarani-Nikravesh,
5000 rpm): d(peak crank moment in the first millisecond)/d(clearance, restitution) from forward sensitivities
through every impact, against central differences of separate runs; then the growth of the sensitivities over
the first revolution at c = 0.5 and 0.1 mm, with their finite-time Lyapunov estimate and predictability horizon.
Until ``simulate(..., sensitivities=...)`` lands in the run driver this uses the reference run (slow).

Writes into ``--out`` (default ``results/sensitivity_study/``): ``gradients.json`` and
``sensitivity_horizon.png``. Run: ``python examples/sensitivity_study.py`` (``--quick``: 0.4 ms and 2 ms).
"""

from __future__ import annotations

import argparse
import json
import warnings
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402
from daeclear.assembly.sensitivity import parameter_value  # noqa: E402
from daeclear.plot import plot_sensitivity_horizon  # noqa: E402
from daeclear.results.sensitivity_growth import relative_growth  # noqa: E402

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


def growth(clearance: float, span: float) -> tuple[np.ndarray, np.ndarray]:
    """G(t), the largest relative sensitivity to the clearance and the restitution, over ``span``."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=clearance))
    run = dc.simulate(model, span, rtol=1e-8, save=dc.SaveAt(times=np.linspace(0.0, span, 201), steps=False),
                      sensitivities=PARAMETERS, on_failure="return")
    n = 2 * model.n_q  # positions and velocities, each against its largest magnitude over the run
    scale = np.maximum(np.abs(run.y[:, :n]).max(axis=0), 1e-12)
    p = [parameter_value(model, name) for name in PARAMETERS]
    S = np.stack([run.sensitivity(name) for name in run.state_names[:n]], axis=1)  # (n_times, n, Ns)
    return run.t, relative_growth(S, scale, p)


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = {"gradients": gradients(0.4e-3 if args.quick else 1e-3)}
        fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
        for ax, clearance in zip(axes, (0.5e-3, 0.1e-3)):
            t, g = growth(clearance, 2e-3 if args.quick else 12e-3)
            plot_sensitivity_horizon(t, g, 1e-8, ax=ax, label=f"c = {clearance * 1e3:g} mm")
    path = args.out / "sensitivity_horizon.png"
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    (args.out / "gradients.json").write_text(json.dumps(result, indent=2))
    print(f"wrote {path} and {args.out / 'gradients.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
