"""Section 4.4, Figs. 4.16-4.18: the revolute clearance-size study as a sweep (c = 0.5, 0.2, 0.1, 0.01 mm).

Every value is one run classified by :func:`daeclear.analysis.classify_motion` (periodic of
period k, quasi-periodic or chaotic, with the evidence), run in parallel by :func:`daeclear.sweep`
and gathered in ``results/sweep_revolute_clearance/revolute_clearance.h5``; running the script again resumes
the sweep and recomputes nothing that is finished. Outputs and options: ``sweep_studies.py``.

Run: ``python examples/sweep_revolute_clearance.py`` (``--quick`` for a smoke run, ``--dask local``
for a local Dask cluster).
"""

from __future__ import annotations

import sys
from pathlib import Path
from collections.abc import Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))

import sweep_studies  # noqa: E402


def main(argv: Sequence[str] | None = None) -> int:
    return sweep_studies.main("revolute_clearance", argv)


if __name__ == "__main__":
    sys.exit(main())
