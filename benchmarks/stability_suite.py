"""Run the stability suite (daeclear.stability.CASES) and print its table; --write updates docs/stability.md.

    python benchmarks/stability_suite.py [--rtol 1e-6] [--write]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from daeclear.stability import CASES, run_suite, to_markdown


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
                        f"`python benchmarks/stability_suite.py --rtol {args.rtol:g} --write`.\n\n" + table)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
