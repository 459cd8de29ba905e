"""Figs. 4.22-4.24: contact force laws (Hertz, Lankarani-Nikravesh, Dubowsky-Freudenstein, Goldsmith, ESDU 78035).

Section 4.4's contact-law study: c = 0.5 mm, no friction, 5000 rpm, gravity 9.81 m/s^2, IDA at
rtol 1e-6. Transient and windows as in ``_common.py``.

- Hertz: F = K delta^1.5, K = 6.61e10 N/m^1.5 from eq. (3.5) (elastic);
- Lankarani-Nikravesh (3.9): same K, c_e = 0.9 (the only dissipative law here);
- Dubowsky-Freudenstein, Goldsmith, ESDU 78035: the implicit cylindrical laws of
  docs/contact_laws.md (elastic), with axial contact length L = 10 mm (``--length``).
  The chapter does not give L; section 8.7 shows that L = 10-20 mm makes the cylindrical
  laws "reasonably close" to Hertz, as the chapter's summary says; we take the short end.
  sigma convention: daeclear's defaults, (1 - nu^2)/E for Dubowsky-Freudenstein and Goldsmith,
  (1 - nu^2)/(pi E) for ESDU 78035 (its Johnson-consistent reading). Goldsmith's form is
  unconfirmed (docs/contact_laws.md).

Writes into ``--out`` (default ``results/revolute_contact_laws/``):

- ``fig4_22_contact_force.png``: contact force for each law;
- ``fig4_23_crank_moment.png``: crank moment, ideal joint dashed;
- ``fig4_24_journal_orbits.png``: journal centre relative to the bearing, one marker per IDA step;
- ``law_curves.png``: the five laws' force against penetration at zero rate (how far apart they are);
- ``step_sizes.png``: IDA's step size, contact shaded;
- ``hertz.h5``, ``lankarani_nikravesh.h5``, ``dubowsky_freudenstein.h5``, ``goldsmith.h5``,
  ``esdu_78035.h5``, ``ideal.h5``: two revolutions;
- ``metrics.json``, ``metrics.md``.

Run: ``python examples/revolute_contact_laws.py`` (``--quick`` for a 5 ms smoke run).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any
from collections.abc import Callable, Sequence

import matplotlib

matplotlib.use("Agg")

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common as cm  # noqa: E402
from daeclear.contact import (  # noqa: E402
    ESDU78035,
    DubowskyFreudenstein,
    Goldsmith,
    Hertz,
    LankaraniNikravesh,
)
from daeclear.plot import style  # noqa: E402
from daeclear.model.mechanisms import BEARING_RADIUS, STEEL, slider_crank  # noqa: E402

CLEARANCE = 0.5e-3  # m
RESTITUTION = 0.9  # Lankarani-Nikravesh only
LENGTH = 10e-3  # m, axial contact length of the cylindrical laws (not given in the chapter)


def laws(length: float) -> dict[str, tuple[str, object]]:
    """Panel label -> (file stem, law object), in the chapter's order (Fig. 4.22 a-e)."""
    mm = f"L = {length * 1e3:g} mm"
    return {
        "Hertz": ("hertz", Hertz()),
        f"Lankarani-Nikravesh, $c_e$ = {RESTITUTION:g}": ("lankarani_nikravesh",
                                                         LankaraniNikravesh(restitution=RESTITUTION)),
        f"Dubowsky-Freudenstein, {mm}": ("dubowsky_freudenstein",
                                         DubowskyFreudenstein(length=length, sigma_convention="plain")),
        f"Goldsmith (form unconfirmed), {mm}": ("goldsmith", Goldsmith(length=length, sigma_convention="plain")),
        f"ESDU 78035, {mm}": ("esdu_78035", ESDU78035(length=length, sigma_convention="pi")),
    }


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``_common.parse_args`` and ``--length`` (m, axial length of the cylindrical laws)."""
    pre = argparse.ArgumentParser(add_help=False)
    pre.add_argument("--length", type=float, default=LENGTH)
    known, rest = pre.parse_known_args(argv)
    args = cm.parse_args(__file__, __doc__.splitlines()[0] + f" [--length L, m, default {LENGTH:g}]", rest)
    args.length = known.length
    return args


def run(args: argparse.Namespace) -> cm.Study:
    """Simulate the ideal joint and the five laws."""
    scenes = {label: (stem, slider_crank("revolute", clearance=CLEARANCE, law=law, gravity=cm.GRAVITY, rpm=cm.RPM))
              for label, (stem, law) in laws(args.length).items()}
    return cm.run_study(f"Figs. 4.22-4.24: contact laws, c = 0.5 mm, frictionless, cylindrical laws with "
                        f"L = {args.length * 1e3:g} mm", scenes, args)


def figures(study: cm.Study, length: float = LENGTH) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure (titles: what it shows and the shared parameters)."""
    return {
        "fig4_22_contact_force.png": lambda: cm.channel_figure(study, "clearance.normal_force",
                                                               "Fig. 4.22: contact force", reference=False),
        "fig4_23_crank_moment.png": lambda: cm.channel_figure(study, "drive.moment", "Fig. 4.23: crank moment"),
        "fig4_24_journal_orbits.png": lambda: cm.orbit_figure(
            study, "Fig. 4.24: journal centre trajectory (one marker per IDA step)"),
        "law_curves.png": lambda: _law_curves(laws(length)),
        "step_sizes.png": lambda: cm.step_figure(study, "IDA step size, contact shaded"),
    }


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    study = run(args)
    for name, draw in figures(study, args.length).items():
        cm.save_figure(draw(), args.out / name)
    cm.save_study(study, args.out, args.rtol)
    cm.print_written(args.out)
    return 0


def _law_curves(chosen: dict[str, tuple[str, object]]):
    """Force against penetration (rate 0) of every law, resolved for the c = 0.5 mm journal."""
    import matplotlib.pyplot as plt
    import numpy as np

    delta = np.linspace(0.0, 80e-6, 401)
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for label, (_, law) in chosen.items():
        resolved = law.resolve("internal_cylinder", radii=(BEARING_RADIUS, BEARING_RADIUS - CLEARANCE),
                               materials=STEEL)
        ax.plot(delta * 1e6, resolved.force(delta, np.zeros_like(delta), np.ones_like(delta)) / 1e3, label=label)
    ax.set_xlabel("penetration (µm)")
    ax.set_ylabel("contact force at zero rate (kN)")
    clearance = style.format_parameter("clearance", CLEARANCE)
    style.set_title(ax, f"Normal laws for the journal in the bearing\n{clearance}, steel, penetration rate 0")
    ax.legend(fontsize="small")
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    sys.exit(main())
