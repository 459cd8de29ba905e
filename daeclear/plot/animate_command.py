"""``daeclear animate``: its arguments and its run (the command line, daeclear.cli, dispatches to it)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..core.errors import DaeclearError

__all__ = ["add_parser", "run"]


def add_parser(sub: Any) -> None:
    """The ``animate`` subcommand's parser, added to ``sub`` (the command line's subparsers)."""
    animate = sub.add_parser(
        "animate", help="animated GIF (or MP4 with ffmpeg) of a saved result",
        description="Draw the mechanism of a saved result moving, each clearance joint magnified in a panel, and "
                    "a time plot with a moving cursor. Frames: round(duration x slow motion x fps), at least 2.")
    animate.add_argument("result", type=Path, help="result file (.h5) written by daeclear run or Result.save")
    animate.add_argument("--out", type=Path, help="animation file, .gif or .mp4 (default: RESULT with .gif)")
    animate.add_argument("--fps", type=float, default=25.0, help="frames per second (default %(default)g)")
    animate.add_argument("--window", type=float, nargs=2, metavar=("T0", "T1"),
                         help="simulated time shown, s (default: the whole run)")
    animate.add_argument("--slow-motion", type=float,
                         help="times slower than real time (default: the window plays in 5 s)")
    size = (720, 450)
    animate.add_argument("--size", type=int, nargs=2, default=size, metavar=("WIDTH", "HEIGHT"),
                         help=f"pixels (default {size[0]} {size[1]})")
    animate.add_argument("--channel", help="channel of the time plot (default: the driver's moment)")
    animate.add_argument("--magnify", type=float,
                         help="magnification of a slider's offset and tilt in its guide (default: automatic)")
    animate.add_argument("--quiet", action="store_true", help="no progress line")


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
