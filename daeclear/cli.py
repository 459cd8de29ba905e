"""Command line: ``daeclear run`` a named mechanism or a scene file, writing HDF5 and a figure."""

from __future__ import annotations

import argparse
import ast
import logging
import math
import sys
import warnings
from pathlib import Path
from typing import Any
from collections.abc import Callable, Sequence

from .core.defaults import (CLI_FIGURE_POINTS, CLI_FINEST_STEP, CLI_POINTS, CLI_SHOWN_EVENTS, CLI_STEPS_PER_SECOND,
                            FORMULATION, MAX_OUTPUT_POINTS, MAX_STEPS, RTOL)
from .core.methods import TABLE as METHOD_TABLE
from .core.errors import DaeclearError, DiskFull, Interrupted, PhysicsWarning, SolveError

EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports a program stopped by Ctrl-C
__all__ = ["CLI_FIGURE_POINTS", "CLI_FINEST_STEP", "CLI_POINTS", "CLI_SHOWN_EVENTS", "CLI_STEPS_PER_SECOND",
           "build_parser", "default_max_steps", "default_t_eval_step", "main"]


def _count(n: int) -> str:
    """A count as the docs write it: 1 000 000."""
    return f"{n:,}".replace(",", " ")


def _parse_value(text: str) -> Any:
    """Parse a ``--set`` value: a Python literal (number, string, list, None, bool) or a bare string."""
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def _parse_sets(items: Sequence[str]) -> dict[str, Any]:
    """``--set KEY=VALUE`` items -> {key: value}; a key given twice is an error naming both values."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise DaeclearError(f"--set {item!r}: expected KEY=VALUE, e.g. --set clearance=0.5e-3.")
        key = key.strip()
        if key in out:
            raise DaeclearError(f"--set {key}={value.strip()}: {key} is given twice (--set {key}={out[key]!r} "
                                "before); give it once.")
        text = value.strip()
        out[key] = _parse_value(text)
        if isinstance(out[key], str) and text[:1] in "{[(":  # meant as a table or a list: say why it is not one
            try:
                ast.literal_eval(text)
            except (ValueError, SyntaxError) as exc:
                why = exc.msg if isinstance(exc, SyntaxError) else "a bare name or an expression where a value must be"
                raise DaeclearError(f"--set {key}={text}: not a Python literal ({why}); "
                                    "a table is written with quoted names and numbers only, e.g. --set \"law={'name': "
                                    "'hydrodynamic', 'viscosity': 0.1, 'length': 0.01}\".") from None
    return out


def _mechanism_keys(argv: Sequence[str]) -> str | None:
    """For ``daeclear run|study|sweep MECH --help``: MECH's ``--set`` keys, each with its default and the
    first sentence of its description (units included), read from the mechanism's signature and docstring."""
    if (not ({"-h", "--help"} & set(argv)) or len(argv) < 2 or argv[0] not in ("run", "study", "sweep")
            or argv[1].startswith("-") or argv[1].endswith(".toml")):
        return None
    from .model.mechanism_options import option_table
    from .model.scenefile import MECHANISMS

    if argv[1] not in MECHANISMS:  # not the generic help, as if MECH had no keys: say so
        raise DaeclearError(f"{argv[0]}: {argv[1]!r} is neither a scene file (.toml) nor a mechanism "
                            f"({', '.join(MECHANISMS)}); 'daeclear {argv[0]} --help' describes the command.")
    lines = [f"--set keys of {argv[1]} (KEY=VALUE, a Python literal; default in brackets):"]
    lines += [f"  --set {name}=...  [{default}]  {text}" for name, default, text in option_table(MECHANISMS[argv[1]])]
    return "\n".join(lines)


def build_parser(argv: Sequence[str] = ()) -> argparse.ArgumentParser:
    """The command line's parser; ``argv`` (when asking for help) adds a mechanism's --set keys to its help."""
    parser = argparse.ArgumentParser(prog="daeclear", description="Planar mechanisms with clearance joints.")
    sub = parser.add_subparsers(dest="command", required=True)
    keys = _mechanism_keys(argv)
    epilog = keys or "daeclear run MECH --help lists the --set keys of mechanism MECH with their defaults and units."
    formatter = argparse.RawDescriptionHelpFormatter
    run = sub.add_parser("run", help="simulate a named mechanism or a scene file (.toml)", epilog=epilog,
                         formatter_class=formatter)
    run.add_argument("target", help="mechanism name (slider_crank, chain, four_bar, double_pendulum) or path to a "
                                    ".toml scene file")
    run.add_argument("--joint", help="slider_crank: which joint has clearance (ideal, revolute, translational)")
    run.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                     help="mechanism parameter, e.g. --set rpm=3000, --set n_links=4 or --set clearance_joints=B,C "
                          "(repeatable)")
    run.add_argument("--t-end", type=float,
                     help="end time, s (default: two revolutions of the driver; 0.024 s without one)")
    run.add_argument("--rtol", type=float, help=f"relative tolerance (default {RTOL:g})")
    run.add_argument("--max-steps", type=int, metavar="N",
                     help=f"cap on IDA's steps (default: {_count(CLI_STEPS_PER_SECOND)} per simulated second, at "
                          f"least {_count(MAX_STEPS)})")
    points = run.add_mutually_exclusive_group()
    points.add_argument("--t-eval-step", type=float, metavar="DT",
                        help=f"report the run every DT seconds (default: the scene file's t_eval_step, else "
                             f"t_end / {CLI_POINTS} but no finer than {CLI_FINEST_STEP:g} s: at most "
                             f"{_count(CLI_POINTS + 1)} points)")
    points.add_argument("--every-step", action="store_true",
                        help="report every IDA step (memory and file grow with the run, ~1.7 MB per revolution "
                             "of the chapter's slider-crank)")
    run.add_argument("--max-points", type=int, metavar="N",
                     help=f"refuse before the run to report more than N points (default {_count(MAX_OUTPUT_POINTS)}, "
                          "about 1 GB for the chapter's slider-crank; the message gives the estimated size)")
    run.add_argument("--formulation", choices=["index1", "ggl"],
                     help=f"DAE formulation (default {FORMULATION}; index1: the chapter's)")
    run.add_argument("--backend", choices=["auto", "c", "python"], default="auto",
                     help="model and IDA loop in generated C (c), in scikit-sundae (python), or c when a compiler "
                          "is found (default %(default)s)")
    run.add_argument("--out", type=Path, default=Path("results"), help="output directory (default ./%(default)s)")
    run.add_argument("--name", help="base name of the output files (default: the scene name)")
    run.add_argument("--sensitivity", action="append", default=[], metavar="NAME",
                     help="integrate d(states)/d(NAME) too, NAME from model.parameter_names (repeatable): saved in "
                          "the file, drawn in BASE_sensitivities.png (IDA; small models, short spans)")
    run.add_argument("--no-figure", action="store_true", help="write the HDF5 result only")
    run.add_argument("--window", type=float, nargs=2, metavar=("T0", "T1"),
                     help="the figure shows this time window, s (default: the whole run, min-max decimated to "
                          f"{CLI_FIGURE_POINTS} points a curve so that peaks survive; the file has every point)")
    run.add_argument("--quiet", action="store_true", help="no progress line")

    study = sub.add_parser("study", help="work-precision study: error against run time per method and tolerance",
                           epilog=epilog, formatter_class=formatter)
    study.add_argument("target", help="mechanism name (slider_crank)")
    study.add_argument("--joint", help="slider_crank: which joint has clearance (default revolute)")
    study.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="mechanism parameter")
    study.add_argument("--t-end", type=float, default=0.012,
                       help="end time, s (default %(default)s: one revolution at 5000 rpm)")
    study.add_argument("--methods", default="ida,DOP853,LSODA,rk4",
                       help=f"comma-separated methods ({', '.join(m.name for m in METHOD_TABLE)}; "
                            "default %(default)s)")
    study.add_argument("--rtols", default="1e-4,1e-6,1e-8",
                       help="tolerances of the adaptive methods (default %(default)s)")
    study.add_argument("--steps", default="1e-5,5e-6", help="steps of the fixed-step methods, s (default %(default)s)")
    study.add_argument("--channels", default="slider.vx,drive.moment",
                       help="channels whose error is measured (default %(default)s)")
    study.add_argument("--repeats", type=int, default=3, help="timed repeats per run, best kept (default %(default)s)")
    study.add_argument("--out", type=Path, default=Path("results/study"), help="output directory (default %(default)s)")
    _add_sweep_parser(sub, epilog)
    _add_animate_parser(sub)
    return parser


def _add_joint(target: str, joint: str | None, params: dict[str, Any]) -> None:
    """Put ``--joint`` (the slider-crank's option only; not with --set joint=) into the mechanism's parameters."""
    if joint is None:
        return
    if target != "slider_crank":
        raise DaeclearError(f"--joint {joint}: --joint is the slider-crank's option; {target} chooses its clearance "
                            f"joints with --set clearance_joints=A,B (see daeclear run {target} --help).")
    if "joint" in params:
        raise DaeclearError(f"--joint {joint}: joint is given twice (--set joint={params['joint']!r} too); "
                            "give it once.")
    params["joint"] = joint


def _mechanism(mechanisms: dict[str, Any], name: str, params: dict[str, Any]) -> Any:
    """Build a named mechanism; a missing required parameter (chain's n_links) is a clear error."""
    try:
        return mechanisms[name](**params)
    except TypeError as exc:
        raise DaeclearError(f"{name}: {exc} (give it with --set KEY=VALUE).") from None


def _run(args: argparse.Namespace) -> int:
    from .core import options
    from .model.mechanism_options import ideal_parameters
    from .results.outputs import check_directory
    from .model.scene import RevoluteClearance, TranslationalClearance
    from .model.scenefile import MECHANISMS, read_scene_file
    from .solvers.save_at import SaveAt
    from .solvers.solver_options import SolverOptions
    from .solvers.dispatch import simulate

    where = "daeclear run"
    params = _parse_sets(args.set)
    sim: dict[str, Any] = {}
    reference_scene = None
    if args.target.endswith(".toml") or Path(args.target).is_file():
        spec = read_scene_file(args.target)  # checks its [simulate] options by the shared rules
        scene, sim = spec.scene, dict(spec.simulate)
        if any(isinstance(j, (RevoluteClearance, TranslationalClearance)) for j in scene.joints):
            reference_scene = scene.ideal()  # the figure compares with the ideal mechanism
        if params or args.joint:
            raise DaeclearError("--set and --joint apply to named mechanisms; edit the scene file instead.")
    elif args.target in MECHANISMS:
        _add_joint(args.target, args.joint, params)
        scene = _mechanism(MECHANISMS, args.target, params)
        ideal = ideal_parameters(args.target, params)
        if ideal is not None:  # the chapter plots against the ideal mechanism
            reference_scene = MECHANISMS[args.target](**ideal)
    else:
        raise DaeclearError(f"run: {args.target!r} is neither a scene file nor a mechanism "
                            f"({', '.join(MECHANISMS)}).")
    # an option given is checked, never replaced by a default (--t-end 0 is an error, not "two revolutions")
    t_end = sim.pop("t_end", None)
    if args.t_end is not None:
        t_end = options.t_end(args.t_end, where=where, field="--t-end")
    elif t_end is None:  # two revolutions of the first driver; 24 ms (two at the chapter's 5000 rpm) without one
        speed = abs(float(scene.drivers[0].speed or 0.0)) if scene.drivers else 0.0
        t_end = 4.0 * math.pi / speed if speed else 0.024
    rtol = options.rtol(args.rtol, where=where, field="--rtol") if args.rtol is not None else sim.pop("rtol", 1e-6)
    sim.pop("rtol", None)
    step = sim.pop("t_eval_step", None)
    if args.t_eval_step is not None:
        step = options.t_eval_step(args.t_eval_step, t_end, where=where, field="--t-eval-step")
    elif step is not None:  # the file's spacing, against the end time actually run
        step = options.t_eval_step(step, t_end, where=where + f" {args.target}: [simulate]")
    elif not args.every_step:  # a long run stays affordable: a bounded number of points
        step = default_t_eval_step(t_end)
    base = args.name if args.name is not None else scene.name
    if not base or Path(base).name != base or base in (".", ".."):  # blamed on where the name came from
        field = "--name" if args.name is not None else "--set name" if "name" in params else "[scene] name"
        named = "" if args.name is not None else ", as it names the output files (or give --name)"
        options.fail(where if args.name is not None else f"{where} {args.target}", field, base,
                     f"a plain file name without a directory (e.g. run1){named}")
    figures = [f"{base}.png", *([f"{base}_sensitivities.png"] if args.sensitivity else [])]
    check_directory(args.out, "--out", files=[f"{base}.h5", *figures])  # before any work
    if args.window is not None:  # the figure's window, inside the run
        lo, hi = args.window
        if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 <= lo < hi and lo < t_end):
            options.fail(where, "--window", tuple(args.window), f"T0 < T1 with 0 <= T0 < t_end={t_end:g} s", "s")
    settings: dict[str, Any] = {"backend": args.backend, **sim}
    if args.formulation:
        settings["formulation"] = args.formulation
    h5 = args.out / f"{base}.h5"
    # streamed: the file holds what was computed whatever stops the run, in bounded memory
    output: dict[str, Any] = {"stream_to": h5, "keep_data": False}
    if step is not None:  # reported points on a grid; the steps are not kept (bounded memory)
        output.update(every=step, steps=False)
    if args.max_points is not None:
        output["max_points"] = options.max_output_points(args.max_points, where=where, field="--max-points")
    if args.max_steps is not None:
        settings["max_steps"] = options.max_steps(args.max_steps, where=where, field="--max-steps")
    else:  # memory no longer limits a long run: the cap only stops a runaway one
        settings.setdefault("max_steps", default_max_steps(t_end))
    solver, save = SolverOptions(**settings), SaveAt(**output)
    try:
        with warnings.catch_warnings():  # shown once, from the result, after the run
            warnings.simplefilter("ignore", PhysicsWarning)
            outcome = simulate(scene, t_end, rtol=rtol, options=solver, save=save, progress=not args.quiet,
                               on_failure="return", sensitivities=args.sensitivity or None)  # names checked first
        shown_from, result = _read_back(h5)
    except Interrupted as exc:
        message = exc.result.message if exc.result is not None else "interrupted"
        print(f"daeclear: interrupted, partial result saved to {h5} ({message})", file=sys.stderr)
        return EXIT_INTERRUPTED
    except MemoryError:  # reading the result back (the run itself saves what it computed)
        print(f"daeclear: out of memory after the run; the result is in {h5}. Report fewer points "
              "(--t-eval-step) to read it back.", file=sys.stderr)
        return 1
    print(result)
    if shown_from is not None:
        print(f"(the summary above and the figure show t >= {shown_from:.6g} s, the last {CLI_SHOWN_EVENTS} "
              f"of {outcome.stats['n_events']} events; the whole run is in the file)")
    print(f"wrote {h5}")
    for rec in result.warnings:  # also in the HDF5 file
        print(f"daeclear: warning: {rec['kind']}: {rec['message']}", file=sys.stderr)
    try:
        _run_figure(args, result, scene, reference_scene, t_end, rtol, base)
    except KeyboardInterrupt:  # the result is saved already; only the figure is missing
        print(f"daeclear: interrupted, result saved to {h5} (no figure)", file=sys.stderr)
        return EXIT_INTERRUPTED
    if not result.success:
        print(f"daeclear: run failed: {result.message}", file=sys.stderr)
        return 1
    return 0


def _run_figure(args: argparse.Namespace, result: Any, scene: Any, reference_scene: Any, t_end: float, rtol: float,
                base: str) -> None:
    """The response figure of ``daeclear run`` (against the ideal joint when there is one)."""
    if args.no_figure:
        return
    from .solvers.save_at import SaveAt
    from .solvers.solver_options import SolverOptions
    from .solvers.dispatch import simulate
    import matplotlib
    matplotlib.use("Agg")
    from .plot import save_run_figure
    reference = None
    if reference_scene is not None:  # on the run's own output grid: bounded, as the run
        every_step = result.step_t is not None and result.step_t.size == result.n_times
        grid = None if every_step or not result.n_times else SaveAt(times=result.t, steps=False)
        try:
            reference = simulate(reference_scene, t_end, rtol=rtol, on_failure="return",
                                 options=SolverOptions(backend=args.backend), save=grid)
        except DaeclearError as exc:  # e.g. an ideal mechanism with redundant constraints: no dashed lines
            print(f"daeclear: no ideal-mechanism reference in the figure: {exc}", file=sys.stderr)
    png = save_run_figure(result, args.out / f"{base}.png", reference=reference,
                          window=tuple(args.window) if args.window else None, max_points=CLI_FIGURE_POINTS)
    print(f"wrote {png}")
    if result.sensitivities is not None:  # --sensitivity: their growth and horizon too
        from .plot import save_sensitivity_figure
        print(f"wrote {save_sensitivity_figure(result, args.out / f'{base}_sensitivities.png')}")


def _read_back(h5: Path) -> tuple[float | None, Any]:
    """The streamed result, whole, or from the time of its last CLI_SHOWN_EVENTS events on (bounded memory)."""
    from .results.result import load, load_times

    events = load_times(h5, "events")
    shown_from = float(events[-CLI_SHOWN_EVENTS]) if events.size > CLI_SHOWN_EVENTS else None
    return shown_from, load(h5, t0=shown_from)


def default_max_steps(t_end: float) -> int:
    """IDA's step cap of ``daeclear run``: CLI_STEPS_PER_SECOND per simulated second, at least the API's 5e6."""
    return max(MAX_STEPS, math.ceil(CLI_STEPS_PER_SECOND * t_end))


def default_t_eval_step(t_end: float) -> float:
    """The default spacing of ``daeclear run``'s points: ``t_end / CLI_POINTS``, no finer than CLI_FINEST_STEP."""
    return min(t_end, max(CLI_FINEST_STEP, t_end / CLI_POINTS))


def _floats(text: str, what: str) -> list[float]:
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise DaeclearError(f"--{what} {text!r}: expected comma-separated numbers, e.g. 1e-4,1e-6.") from None


def _study(args: argparse.Namespace) -> int:
    from .core import options
    from .studies.accuracy import WorkPrecision, work_precision
    from .results.outputs import check_directory
    from .model.scenefile import MECHANISMS

    where = "daeclear study"
    if args.target not in MECHANISMS:
        raise DaeclearError(f"study: {args.target!r} is not a mechanism ({', '.join(MECHANISMS)}).")
    t_end = options.t_end(args.t_end, where=where, field="--t-end")
    repeats = options.repeats(args.repeats, where=where, field="--repeats")
    names = [m.strip() for m in args.methods.split(",") if m.strip()]
    options.names(names, where=where, field="--methods")
    for i, name in enumerate(names):
        options.method(name, where=where, field=f"--methods[{i}]")
    methods = {m: {"method": m} for m in names}
    channels = options.names([c.strip() for c in args.channels.split(",") if c.strip()], where=where,
                             field="--channels")
    rtols = options.rtols(_floats(args.rtols, "rtols"), where=where, field="--rtols")
    steps = options.steps(_floats(args.steps, "steps"), t_end, where=where, field="--steps")
    params = _parse_sets(args.set)
    _add_joint(args.target, args.joint, params)
    if args.target == "slider_crank":
        params.setdefault("joint", "revolute")
    scene = _mechanism(MECHANISMS, args.target, params)
    files = ("work_precision.csv", "work_precision.md", "work_precision.png")
    check_directory(args.out, "--out", files=files)  # before any work
    try:
        study = work_precision(scene, t_end, channels=channels, methods=methods, rtols=rtols, steps=steps,
                               repeats=repeats, progress=True)
    except Interrupted as exc:
        if isinstance(exc.result, WorkPrecision) and exc.result.rows:
            try:
                _write_study_tables(exc.result, args.out)
            except KeyboardInterrupt:  # a Ctrl-C held back during the write: the tables are complete
                pass
            print(f"daeclear: interrupted, partial result saved to {args.out / files[0]} and .md "
                  f"({len(exc.result.rows)} finished runs)", file=sys.stderr)
        else:
            print("daeclear: interrupted before the first study run finished; nothing saved", file=sys.stderr)
        return EXIT_INTERRUPTED
    text = _write_study_tables(study, args.out)
    from .plot import plot_work_precision

    _save_figure(args.out / "work_precision.png", (6.5, 4.5), plot_work_precision, study)
    print(text)
    others = [label for label in methods if label.lower() != "ida"]
    for row in study.speed_ratio("ida", others) if "ida" in methods else []:
        print(f"ida rtol {row['tolerance']:g}: error {row['error']:.3g}, {row['wall_time']:.4f} s; fastest other at "
              f"equal or better accuracy: {row['rival']} ({row['rival_wall_time']:.4f} s): ratio {row['ratio']:.1f}")
    print(f"wrote {args.out / 'work_precision.csv'}, .md and .png")
    return 0


def _save_figure(png: Path, size: tuple[float, float], plot: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
    """One figure of ``size`` inches drawn by ``plot(*args, ax=ax, **kwargs)``, saved to ``png`` at 120 dpi."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=size)
    plot(*args, ax=ax, **kwargs)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)


def _write_study_tables(study: Any, out: Path) -> str:
    """The study's CSV and markdown tables, each written whole (atomic, Ctrl-C deferred); the markdown text."""
    from .results.outputs import atomic_write_text, deferred_sigint

    text = study.to_markdown()
    with deferred_sigint():  # both tables, or a second Ctrl-C waits until both are written
        atomic_write_text(out / "work_precision.csv", study.to_csv())
        atomic_write_text(out / "work_precision.md", text)
    return text


def _add_sweep_parser(sub: Any, epilog: str) -> None:
    sweep = sub.add_parser("sweep", help="classify the motion over a grid of parameters into one HDF5 file",
                           description="Run and classify (periodic, quasi-periodic, chaotic) one scene per parameter "
                                       "point, in parallel, into one HDF5 file; an interrupted sweep resumes where it "
                                       "stopped when the same command is run again.", epilog=epilog,
                           formatter_class=argparse.RawDescriptionHelpFormatter)
    sweep.add_argument("target", help="mechanism name (slider_crank)")
    sweep.add_argument("out", type=Path, help="sweep file (.h5), created or resumed")
    sweep.add_argument("--joint", help="slider_crank: which joint has clearance (ideal, revolute, translational)")
    sweep.add_argument("--grid", action="append", default=[], metavar="NAME=VALUES",
                       help="swept parameter: NAME=v1,v2,... or NAME=lin:START:STOP:N or NAME=geom:START:STOP:N "
                            "(repeatable: every combination is run)")
    sweep.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="fixed mechanism parameter, e.g. --set rpm=3000 (repeatable)")
    sweep.add_argument("--points", type=Path, help="JSON file with a list of parameter points (dicts) to run")
    sweep.add_argument("--revolutions", type=int, default=30, help="revolutions analysed (default %(default)s)")
    sweep.add_argument("--transient", type=int, default=10, help="revolutions discarded first (default %(default)s)")
    sweep.add_argument("--per-revolution", type=int, default=32,
                       help="output samples per revolution (default %(default)s)")
    sweep.add_argument("--channels", help="Poincaré-section channels (default: slider.vx,slider.ax with a body "
                                          "named slider, else the last body's omega,alpha)")
    sweep.add_argument("--twin", choices=["always", "auto", "never"], default="always",
                       help="twin runs for the chaos test: always (default), only when the section does not "
                            "recur (auto), or never")
    sweep.add_argument("--rtol", type=float, default=RTOL, help="IDA relative tolerance (default %(default)g)")
    sweep.add_argument("--keep", choices=["section", "channels", "full"], default="channels",
                       help="what each run stores besides its class and section (default %(default)s)")
    sweep.add_argument("--workers", type=int, help="worker processes (default: the CPU count)")
    sweep.add_argument("--dask", metavar="ADDRESS",
                       help="run on a Dask cluster: a scheduler address (tcp://host:8786) or 'local'")
    sweep.add_argument("--restart", action="store_true", help="discard the file's runs and start over")
    sweep.add_argument("--retry-failed", action="store_true", help="run the recorded failed runs again")
    sweep.add_argument("--no-figure", action="store_true", help="no bifurcation diagram / motion map")
    sweep.add_argument("--quiet", action="store_true", help="no progress line")


def _grid_values(item: str) -> tuple[str, list[Any]]:
    """``NAME=v1,v2``, ``NAME=lin:a:b:n`` or ``NAME=geom:a:b:n`` -> (name, values)."""
    import numpy as np

    name, sep, text = item.partition("=")
    name, text = name.strip(), text.strip()
    if not sep or not name or not text:
        raise DaeclearError(f"--grid {item!r}: expected NAME=v1,v2,... or NAME=lin:START:STOP:N, "
                            "e.g. --grid clearance=0.01e-3,0.1e-3,0.5e-3.")
    kind, _, spec = text.partition(":")
    if kind in ("lin", "geom") and spec:
        try:
            a, b, n = spec.split(":")
            start, stop, count = float(a), float(b), int(n)
        except ValueError:
            raise DaeclearError(f"--grid {item!r}: expected {kind}:START:STOP:N, e.g. {kind}:1e-5:5e-4:10.") from None
        if count < 1 or (kind == "geom" and (start <= 0 or stop <= 0)):
            rule = " and START, STOP > 0." if kind == "geom" else "."
            raise DaeclearError(f"--grid {item!r}: N must be >= 1{rule}")
        values = np.linspace(start, stop, count) if kind == "lin" else np.geomspace(start, stop, count)
        return name, [float(v) for v in values]
    if spec and kind.isidentifier():  # e.g. log:1e-5:5e-4:10, a kind that does not exist
        raise DaeclearError(f"--grid {item!r}: unknown grid kind {kind!r}; the kinds are NAME=v1,v2,... (values), "
                            "NAME=lin:START:STOP:N (evenly spaced) and NAME=geom:START:STOP:N (geometric).")
    return name, [_parse_value(v.strip()) for v in text.split(",") if v.strip()]


def _sweep(args: argparse.Namespace) -> int:
    import json

    from .core import options
    from .results.outputs import check_directory, check_file
    from .studies.sweep import sweep

    fixed = _parse_sets(args.set)
    _add_joint(args.target, args.joint, fixed)
    grid: dict[str, list[Any]] = {}
    for item in args.grid:  # a parameter swept twice, or swept and fixed, is a contradiction
        key, swept = _grid_values(item)
        if key in grid:
            raise DaeclearError(f"--grid {item!r}: {key} is swept twice (--grid {key}={grid[key]!r} before); "
                                "give it once.")
        if key in fixed:
            given = f"--joint {fixed[key]}" if key == "joint" and args.joint else f"--set {key}={fixed[key]!r}"
            raise DaeclearError(f"--grid {item!r}: {key} is also fixed by {given}; sweep it or fix it, not both.")
        grid[key] = swept
    points = None
    if args.points:
        try:
            points = json.loads(args.points.read_text())
        except (OSError, ValueError) as exc:
            raise DaeclearError(f"--points {args.points}: cannot read a JSON list of points ({exc}).") from None
        if not isinstance(points, list) or not all(isinstance(p, dict) for p in points):
            raise DaeclearError(f"--points {args.points}: expected a JSON list of objects, e.g. "
                                '[{"clearance": 1e-4}, {"clearance": 5e-4, "friction": 0.1}].')
    if not grid and not points:
        raise DaeclearError("sweep: give --grid NAME=VALUES (repeatable) and/or --points FILE.json.")
    where = "daeclear sweep"
    options.revolutions(args.revolutions, where=where, field="--revolutions")
    options.transient(args.transient, where=where, field="--transient")
    options.per_revolution(args.per_revolution, where=where, field="--per-revolution")
    options.rtol(args.rtol, where=where, field="--rtol")
    options.workers(args.workers, where=where, field="--workers")
    channels = None
    if args.channels is not None:
        channels = [c.strip() for c in args.channels.split(",") if c.strip()]
        options.names(channels, where=where, field="--channels")
    if not args.out.parent.exists():
        check_directory(args.out.parent, "daeclear sweep OUT (its directory)")
    check_file(args.out, "daeclear sweep OUT", what="a sweep file (.h5)", example="sweep.h5")  # before any work
    client = cluster = executor = None
    if args.dask:
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError:
            raise DaeclearError("--dask needs Dask: pip install 'daeclear[dask]' (dask[distributed]).") from None
        if args.dask == "local":
            cluster = LocalCluster(n_workers=args.workers or 2, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        else:
            client = Client(args.dask)
        executor = client.get_executor()
    twin = "auto" if args.twin == "auto" else args.twin == "always"
    try:
        result = sweep(args.out, grid or None, runs=points, mechanism=args.target, fixed=fixed,
                       channels=channels, keep=args.keep,
                       revolutions=args.revolutions, transient=args.transient, per_revolution=args.per_revolution,
                       twin=twin, rtol=args.rtol, executor=executor, max_workers=args.workers,
                       resume=not args.restart, retry_failed=args.retry_failed, progress=not args.quiet)
    except KeyboardInterrupt:
        print(f"daeclear: interrupted, partial result saved to {args.out} (the finished runs). Run the same command "
              "again to resume.", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    names = result.parameter_names()
    print(f"{result}  ({result.n_computed} computed now, {result.n_skipped} already done)")
    for run in result.runs:
        values = " ".join(f"{n}={run.parameters.get(n)!r}" for n in names)
        if run.ok:
            e = run.evidence
            print(f"  {values}: {run.motion}" + (f" (period {run.period})" if run.motion == "periodic" else "")
                  + f"  defect {e.get('periodicity_defect', float('nan')):.3g}"
                  + (f", decorrelation {e['decorrelation']:.3g}" if "decorrelation" in e else "")
                  + (f", Lyapunov {e['lyapunov']:.3g} 1/s" if "lyapunov" in e else ""))
        else:
            print(f"  {values}: FAILED {run.error}")
    numeric = [n for n in names if all(isinstance(r.parameters.get(n), (int, float))
                                       and not isinstance(r.parameters.get(n), bool) for r in result.runs)]
    if not args.no_figure and result.runs and 1 <= len(names) <= 2:
        from .plot import plot_bifurcation, plot_motion_map

        if len(names) == 1 and numeric:
            png = args.out.with_name(args.out.stem + "_bifurcation.png")
            _save_figure(png, (7.0, 4.5), plot_bifurcation, result, names[0], title=True)
        else:
            png = args.out.with_name(args.out.stem + "_motion_map.png")
            _save_figure(png, (7.0, 4.5), plot_motion_map, result, names[0], names[-1], title=True)
        print(f"wrote {png}")
    if result.failed:
        print(f"daeclear: {len(result.failed)} run(s) failed (recorded in {args.out}; --retry-failed runs them "
              "again).", file=sys.stderr)
        return 1
    return 0


def _add_animate_parser(sub: Any) -> None:
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


def main(argv: Sequence[str] | None = None) -> int:
    logging.basicConfig(level=logging.WARNING, format="daeclear: %(message)s")
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        parser = build_parser(argv)
    except DaeclearError as exc:  # daeclear run UNKNOWN --help
        print(f"daeclear: error: {exc}", file=sys.stderr)
        return 2
    args = parser.parse_args(argv)
    try:
        if args.command == "run":
            return _run(args)
        if args.command == "study":
            return _study(args)
        if args.command == "sweep":
            return _sweep(args)
        if args.command == "animate":
            from .plot.animate_command import run as animate  # loads the figures' libraries

            return animate(args)
    except SolveError as exc:
        print(f"daeclear: {exc}", file=sys.stderr)
        return 1
    except DiskFull as exc:  # the file named holds what was written before (a run: marked incomplete)
        print(f"daeclear: error: {exc}", file=sys.stderr)
        return 1
    except (DaeclearError, ValueError, KeyError) as exc:
        print(f"daeclear: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # Ctrl-C outside a run (assembly, compiling, a figure): nothing to save
        print("daeclear: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except (OSError, RuntimeError) as exc:  # a write that failed after the checks (disk full, ...): one line
        from .results.outputs import is_disk_full

        if not isinstance(exc, OSError) and not is_disk_full(exc):
            raise
        name = getattr(exc, "filename", None)
        where = f" writing '{name}'" if name else ""
        cause = "no space left on the disk" if is_disk_full(exc) else str(exc).splitlines()[0]
        print(f"daeclear: error{where}: {cause} ({type(exc).__name__}).", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
