"""``daeclear animate``: its run (the command line, daeclear.cli, parses its arguments and dispatches to it)."""

from __future__ import annotations

import argparse

from ..core.errors import DaeclearError

__all__ = ["run"]


def run(args: argparse.Namespace) -> int:
    """``daeclear animate``: the animation of a saved result."""
    from ..results.result import load
    from .animate import CLI_FIELDS, render

    if not args.result.is_file():
        raise DaeclearError(f"animate: no result file '{args.result}'; give a .h5 file written by daeclear run or "
                            "Result.save.")
    out = args.out if args.out is not None else args.result.with_suffix(".gif")
    result = load(args.result)
    path = render(result, out, fps=args.fps, window=tuple(args.window) if args.window else None,
                  slow_motion=args.slow_motion, size=tuple(args.size), channel=args.channel, magnify=args.magnify,
                  progress=not args.quiet, fields=CLI_FIELDS)
    print(f"wrote {path}")
    return 0
