"""The figure gallery: one representative figure per figure family of sections 4.4 and 4.5.

Runs every example script's cases in this process (each script's ``run`` and ``figures``, with
the scripts' default settings: 4 revolutions of transient, 20 analysed for section 4.4 and 10 for
section 4.5, the last two plotted; nothing but the PNGs is written), and writes one small PNG
per family into ``--out`` (default ``results/gallery/`` in the current directory, as every example
script): 90 dpi, quantized to a 256-colour palette, the figure title also in the PNG's ``Title``
text; ``--doc PAGE`` also writes the page that shows them. The committed gallery is made by
``python examples/gallery.py --out docs/figures/gallery --doc docs/gallery.md``: only a command that
names them writes into the checkout.

Every figure is titled with the parameters of its runs (``daeclear.plot.style.caption``): clearance,
crank speed, contact law and restitution, friction; a figure comparing cases states the shared
parameters in its title and the varied one in its panel titles or legend.

Run ``python examples/gallery.py`` (about 25 s on 2 cores, 35 s on an empty compile cache), ``--quick`` for 5 ms runs
(smoke test: same file names, the figures show only the start-up).
"""

from __future__ import annotations

import argparse
import importlib
import io
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import _common as cm  # noqa: E402

ROOT = HERE.parent
DEFAULT_OUT = Path("results") / "gallery"  # in the current directory, as every example script writes
COMMITTED = ROOT / "docs" / "figures" / "gallery"  # the gallery docs/gallery.md shows
#: The command that makes the committed gallery and its page (the only one that writes into the checkout).
REGENERATE = "python examples/gallery.py --out docs/figures/gallery --doc docs/gallery.md"
DPI = 90


@dataclass(frozen=True)
class Family:
    """One figure family: the script that makes it, its figure shown here, the gallery file and caption."""

    chapter: str  # the chapter's figures of the family
    script: str  # example script (module name)
    figure: str  # the script's file name of the figure shown
    file: str  # gallery file name
    caption: str  # what the chapter's figure shows


FAMILIES: tuple[Family, ...] = (
    Family("Fig. 4.15", "revolute_fig4_15", "fig4_15.png", "fig4_15_response.png",
           "slider velocity, acceleration and crank moment against the ideal joint, and the journal orbit "
           "(one marker per IDA step) for the 0.5 mm revolute clearance"),
    Family("Figs. 4.16-4.18", "revolute_clearance_study", "fig4_17_journal_orbits.png",
           "fig4_17_journal_orbits.png",
           "clearance size c = 0.5, 0.2, 0.1, 0.01 mm: journal centre relative to the bearing (Fig. 4.17); "
           "the script also draws the crank moment (4.16) and the phase portraits (4.18)"),
    Family("Figs. 4.19-4.21", "revolute_friction_study", "fig4_21_phase_portraits.png",
           "fig4_21_phase_portraits.png",
           "friction c_f = 0.01, 0.03, 0.05, 0.1 (modified Coulomb): slider acceleration against velocity with "
           "one point per revolution (Fig. 4.21); also the crank moment (4.19) and the orbits (4.20)"),
    Family("Figs. 4.22-4.24", "revolute_contact_laws", "fig4_22_contact_force.png", "fig4_22_contact_force.png",
           "five contact laws (Hertz, Lankarani-Nikravesh, Dubowsky-Freudenstein, Goldsmith, ESDU 78035): "
           "contact force (Fig. 4.22); also the crank moment (4.23) and the orbits (4.24)"),
    Family("Fig. 4.25", "revolute_restitution", "fig4_25_crank_moment.png", "fig4_25_crank_moment.png",
           "coefficient of restitution c_e = 1.00, 0.99, 0.95, 0.90: crank moment against the ideal joint"),
    Family("Fig. 4.26", "revolute_first_impact", "fig4_26_first_impact.png", "fig4_26_first_impact.png",
           "the first impact for each c_e: contact force against time and against penetration (hysteresis loops)"),
    Family("Fig. 4.28", "translational_fig4_28", "fig4_28.png", "fig4_28_response.png",
           "translational clearance joint, c = 0.5 mm: slider velocity, acceleration and crank moment against "
           "the ideal joint, and the dimensionless slider path in the guide"),
    Family("Figs. 4.29-4.31", "translational_fig4_29_31", "fig4_30.png", "fig4_30_slider_paths.png",
           "translational clearance c = 0.5, 0.2, 0.1, 0.01 mm: dimensionless slider path (Fig. 4.30); "
           "also the crank moment (4.29) and the phase portraits (4.31)"),
    Family("Figs. 4.32-4.34", "translational_fig4_32_34", "fig4_32.png", "fig4_32_crank_moment.png",
           "friction in the translational joint, c_f = 0.01, 0.03, 0.05, 0.1: crank moment (Fig. 4.32); "
           "also the slider paths (4.33) and the phase portraits (4.34)"),
    Family("Figs. 4.35-4.36", "translational_fig4_35_36", "fig4_35.png", "fig4_35_contact_force.png",
           "contact model of the translational joint, corner spheres against the linear plane law on faces: "
           "contact force (Fig. 4.35); also the crank moment (4.36)"),
)


def script_argv(family: Family, out: Path, quick: bool) -> list[str]:
    """Options of ``family``'s script for the gallery: its defaults, or ``--quick``."""
    argv = ["--out", str(out / family.script)] + (["--quick"] if quick else [])
    if family.script.startswith("revolute_"):
        argv += ["--jobs", "2"]
    return argv


def make_figure(family: Family, scratch: Path, quick: bool) -> Any:
    """Run ``family``'s script (its ``run``, nothing written) and draw the gallery's figure of it."""
    module = importlib.import_module(family.script)
    args = module.parse_args(script_argv(family, scratch, quick))
    data = module.run(args)
    return module.figures(data)[family.figure]()


def save_small(fig: Any, path: Path, dpi: int = DPI) -> int:
    """Write ``fig`` as a palette PNG (256 colours: a third of the RGBA size) with its title as PNG text;
    close it; return the size in bytes."""
    import matplotlib.pyplot as plt
    from PIL import Image
    from PIL.PngImagePlugin import PngInfo

    title = cm.figure_title(fig)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    plt.close(fig)
    image = Image.open(buffer).convert("RGB").quantize(colors=256, method=Image.Quantize.MEDIANCUT)
    info = PngInfo()
    info.add_text("Title", title)
    image.save(path, optimize=True, pnginfo=info)
    return path.stat().st_size


def png_title(path: Path) -> str:
    """The ``Title`` text of a gallery PNG (the figure's title)."""
    from PIL import Image

    with Image.open(path) as image:
        return str(getattr(image, "text", {}).get("Title", ""))


def command(family: Family) -> str:
    """The command that makes the family's full figure set."""
    return f"python examples/{family.script}.py"


def markdown(sizes: dict[str, int], seconds: float) -> str:
    """The gallery page: every image with its caption and the command that regenerates it."""
    total = sum(sizes.values())
    lines = [
        "# Figure gallery",
        "",
        "One figure per figure family of the chapter's sections 4.4 (revolute clearance joint) and 4.5",
        "(translational clearance joint), each titled with the parameters of its runs: clearance, crank speed,",
        "contact law and restitution, friction. A figure comparing cases states the shared parameters in its",
        "title and the varied one in its panel titles or legend.",
        "",
        f"Made by `{REGENERATE}` ({len(sizes)} images, {total / 1e3:.0f} kB, {seconds:.0f} s on the",
        "project's 2-core machine with a warm compile cache): each example script's cases with its default "
        "settings (4 revolutions of",
        "transient discarded, 20 analysed for section 4.4 and 10 for section 4.5, the last two plotted),",
        f"{DPI} dpi. The command under each image makes the family's full figure set, HDF5 results and",
        "metrics into `results/<script>/`; [examples.md](examples.md) describes the scripts. The response at",
        "c = 0.5 mm is chaotic: another tolerance or machine gives other, equally valid, impact sequences",
        "(examples.md, Reproducibility).",
        "",
    ]
    for family in FAMILIES:
        lines += [f"## {family.chapter}", "",
                  f"![{family.chapter}](figures/gallery/{family.file})", "",
                  f"{family.chapter}: {family.caption}. Regenerate: `{command(family)}` "
                  f"(writes `results/{family.script}/{family.figure}`).", ""]
    return "\n".join(lines)


def build(out: Path, *, quick: bool = False, doc: Path | None = None) -> dict[str, str]:
    """Write every gallery PNG into ``out`` (and the page ``doc``); return file name -> figure title."""
    out.mkdir(parents=True, exist_ok=True)
    titles: dict[str, str] = {}
    sizes: dict[str, int] = {}
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="daeclear_gallery_") as scratch:
        for family in FAMILIES:
            t0 = time.perf_counter()
            fig = make_figure(family, Path(scratch), quick)
            titles[family.file] = cm.figure_title(fig)
            sizes[family.file] = save_small(fig, out / family.file)
            print(f"{family.chapter:<16s} {family.file:<30s} {sizes[family.file] / 1e3:6.0f} kB "
                  f"{time.perf_counter() - t0:6.1f} s", flush=True)
    seconds = time.perf_counter() - start
    print(f"gallery: {len(sizes)} images, {sum(sizes.values()) / 1e3:.0f} kB, {seconds:.0f} s -> {out}/")
    if doc is not None:
        doc.write_text(markdown(sizes, seconds) + "\n")
        print(f"wrote {doc}")
    return titles


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="gallery.py", description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="5 ms runs (smoke test), same file names")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help=f"output directory (default {DEFAULT_OUT}/)")
    parser.add_argument("--doc", type=Path, default=None,
                        help=f"also write the page showing the images (default none; the committed: {REGENERATE})")
    args = parser.parse_args(argv)
    build(args.out, quick=args.quick, doc=args.doc)
    return 0


if __name__ == "__main__":
    sys.exit(main())
