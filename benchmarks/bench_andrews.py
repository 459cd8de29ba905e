"""Andrews' squeezing mechanism (examples/andrews_squeezer.py) against the IVP Test Set's reference at
t = 0.03 s: the largest error over the seven joint angles, at rtol 1e-8 ... 1e-12, with both
formulations. The errors are deterministic: ``--write-doc`` writes the table into docs/validation.md
(block "andrews"), where tests/test_doc_numbers.py checks them.

    python benchmarks/bench_andrews.py [--write-doc]
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import daeclear as dc

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from doc_tables import write_block  # noqa: E402

DOC, BLOCK = "docs/validation.md", "andrews"
RTOLS = (1e-8, 1e-9, 1e-10, 1e-11, 1e-12)
FORMULATIONS = (("ggl", "GGL (default)"), ("index1", "index1"))


def example() -> ModuleType:
    """examples/andrews_squeezer.py as a module (its scene, reference and end time)."""
    spec = importlib.util.spec_from_file_location("andrews_squeezer", HERE.parent / "examples" / "andrews_squeezer.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def largest_error(formulation: str, rtol: float, andrews: ModuleType | None = None) -> float:
    """max over the seven angles of |angle(t = 0.03 s) - reference|, rad."""
    andrews = andrews or example()
    result = dc.simulate(andrews.andrews_squeezer(), andrews.T_END, rtol=rtol,
                         options=dc.SolverOptions(formulation=formulation))
    return max(abs(float(result[f"{joint}.angle"][-1]) - ref) for joint, ref in zip(andrews.COORDINATES,
                                                                                  andrews.REFERENCE))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write-doc", action="store_true", help=f"write the table into {DOC}")
    args = parser.parse_args(argv)
    andrews = example()
    lines = ["| formulation | " + " | ".join(f"rtol {r:.0e}" for r in RTOLS) + " |", "|---" * (len(RTOLS) + 1) + "|"]
    for formulation, label in FORMULATIONS:
        errors = [largest_error(formulation, rtol, andrews) for rtol in RTOLS]
        lines.append(f"| {label} | " + " | ".join(f"{e:.2g} rad" for e in errors) + " |")
        print(lines[-1], flush=True)
    if args.write_doc:
        print(f"wrote {write_block(DOC, BLOCK, 'python benchmarks/bench_andrews.py', lines)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
