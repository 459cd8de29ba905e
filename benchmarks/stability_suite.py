"""Run the stability suite (daeclear.studies.stability.CASES) and print its table; --write updates docs/stability.md.

    python benchmarks/stability_suite.py [--rtol 1e-6] [--write]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from daeclear.studies.stability import CASES, run_suite, to_markdown


NOTES = """
Reading the cases that do not pass:

- *clearance 1 um, index1* (the chapter's formulation, no longer the default): every run
  finishes, but the Baumgarte drift of the ideal joints at rtol 1e-6 (about 1 um) is as large as
  the clearance, so the clearance is not resolved. The default GGL formulation (the next row,
  drift 2e-9 m) resolves it.
- *grazing onset, default atol*: the whole penetration (0.3 nm at an approach of 1 um/s) is below
  the default position tolerance (1e-3 * rtol = 1e-9 m), so the impact is not resolved (energy
  residual 2 % of a 5e-14 J kinetic energy). With `atol=1e-12` (next row) it is.
- *plain Coulomb 0.5* is expected to fail: a sticking contact with a friction law that is
  discontinuous at zero sliding speed cannot be integrated (GGL's Newton iteration fails there,
  index-1 chatters until the stall guard stops it); the run stops at once and says to use the
  modified Coulomb law.
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--write", action="store_true", help="write docs/stability.md")
    args = parser.parse_args()
    rows = run_suite(CASES, rtol=args.rtol, progress=True)
    table = to_markdown(rows, args.rtol)
    print(table)
    print(f"{sum(r['passed'] for r in rows)} of {len(rows)} cases passed")
    if args.write:
        path = Path(__file__).resolve().parents[1] / "docs" / "stability.md"
        path.write_text("# Stability suite\n\nStiff and extreme cases: each finishes with bounded energy error and "
                        "constraint drift, or fails with a clear message. Produced by "
                        f"`python benchmarks/stability_suite.py --rtol {args.rtol:g} --write`. Wall times include "
                        "the first compilation of a model (about 2.4 s) where it was not cached yet.\n\n" + table
                        + NOTES)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
