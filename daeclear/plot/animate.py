"""Animations of a run: the mechanism moving, each clearance joint magnified, a time cursor (docs/user_guide.md).

:func:`animate` (``daeclear.animate``, ``daeclear animate RESULT.h5``) checks the options and writes a GIF
(pillow, no external program) or an MP4 (ffmpeg), drawn from the result alone (its scene description and
channels), so a run loaded back from HDF5 animates too. A joint is red in a frame when in contact then or
since the previous frame, so an impact shorter than the frame spacing still shows. The frame is drawn by
:mod:`daeclear.plot.mechanism_frame` and :mod:`daeclear.plot.animation_panels`; matplotlib is imported
only when an animation is made.
"""

from __future__ import annotations

import math
import os
import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..core import options
from . import style
from ..core.errors import MissingDependencyError, SceneError
from ..core.progress import Progress
from .animation_panels import layout_frame
from .run_panels import Window
from .mechanism_frame import (CONTACT, FREE, IMPACT, Geometry, Joint, Sampler, body_pose, contact_state,
                              scene_geometry)

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..results.result import Result

__all__ = ["CONTACT", "DEFAULT_PLAY_TIME", "FREE", "IMPACT", "MAX_FRAMES", "MAX_INSETS", "animate", "frame_count",
           "frame_times"]

DEFAULT_PLAY_TIME = 5.0
"""Seconds the window plays for when ``slow_motion`` is None (then slow_motion = 5 s / D)."""

MAX_FRAMES = 3000
"""Most frames one animation may have (each frame is kept in memory until the file is written)."""

MAX_INSETS = 4
"""Most clearance-joint panels in one animation (the first ones of the scene)."""

MAX_FPS = 100.0
"""Highest frame rate: a GIF stores frame durations in hundredths of a second."""

SIZE_RANGE = (160, 4000)
"""Allowed width and height of an animation, pixels."""

FORMATS = (".gif", ".mp4")
_DPI = 100.0


@dataclass(frozen=True)
class _Fields:
    """How the caller names each option, for error messages (Python keywords or CLI flags)."""

    where: str = "animate"
    path: str = "path"
    fps: str = "fps"
    window: str = "window"
    slow_motion: str = "slow_motion"
    size: str = "size"
    channel: str = "channel"
    magnify: str = "magnify"
    progress: str = "progress"


CLI_FIELDS = _Fields(where="daeclear animate", path="--out", fps="--fps", window="--window",
                     slow_motion="--slow-motion", size="--size", channel="--channel", magnify="--magnify")


def _window(result: Result, window: Window, f: _Fields) -> tuple[float, float]:
    """The closed window [t0, t1] inside the run, t0 < t1 (None: the run's start or end)."""
    t = np.asarray(result.t, dtype=np.float64)
    if t.size < 2 or not t[-1] > t[0]:
        raise SceneError(f"{f.where}: the result has {t.size} output time(s) spanning no time; "
                         "an animation needs a run of nonzero duration.")
    start, end = float(t[0]), float(t[-1])
    sides = "" if f.window.startswith("--") else "; None for its start or end"
    rule = f"(t0, t1) in s with {start:g} <= t0 < t1 <= {end:g} (the run{sides})"
    if window is None:
        return start, end
    try:
        t0, t1 = window
    except (TypeError, ValueError):
        options.fail(f.where, f.window, window, rule)
    lo = start if t0 is None else t0
    hi = end if t1 is None else t1
    for value in (lo, hi):
        if not options.is_real(value) or not math.isfinite(float(value)):
            options.fail(f.where, f.window, window, rule)
    # a window given from printed times (e.g. 0.004 for 0.0040000000000001) is inside the run
    slack = 1e-9 * max(abs(start), abs(end), end - start)
    lo_f, hi_f = float(lo), float(hi)
    if not (start - slack <= lo_f < hi_f <= end + slack):
        shown = ", ".join("None" if v is None else repr(float(v)) for v in (t0, t1))
        options.fail(f.where, f.window, (t0, t1), rule, "s", shown=f"({shown})")
    return max(lo_f, start), min(hi_f, end)


def _size(size: Any, f: _Fields) -> tuple[int, int]:
    lo, hi = SIZE_RANGE
    rule = f"(width, height) in pixels, two integers in [{lo}, {hi}]"
    try:
        w, h = size
    except (TypeError, ValueError):
        options.fail(f.where, f.size, size, rule)
    for value in (w, h):
        if (not isinstance(value, (int, np.integer)) or isinstance(value, (bool, np.bool_))
                or not lo <= int(value) <= hi):
            options.fail(f.where, f.size, size, rule)
    return int(w), int(h)


def frame_count(duration: float, slow_motion: float, fps: float) -> int:
    """Frames of an animation of ``duration`` s of simulated time played ``slow_motion`` times slower than real
    time at ``fps``: ``max(2, round(duration * slow_motion * fps))``; it lasts ``n_frames / fps`` s."""
    return max(2, int(round(duration * slow_motion * fps)))


def frame_times(t0: float, t1: float, n_frames: int) -> NDArray[np.float64]:
    """Simulated time of each frame: ``n_frames`` times evenly spaced from t0 to t1 inclusive."""
    return np.linspace(t0, t1, n_frames)


def _default_channel(result: Result, geo: Geometry, clearance: Sequence[Joint]) -> str:
    """Driver moment, else the first clearance joint's force, else the mechanical energy, else a body angle."""
    candidates = [f"{d}.moment" for d in geo.drivers]
    candidates += [f"{j.name}.normal_force" for j in clearance]
    candidates += ["energy.mechanical", f"{next(iter(geo.bodies))}.phi"]
    return next(c for c in candidates if c in result)


def _check_channel(result: Result, channel: Any, f: _Fields) -> str:
    if not isinstance(channel, str) or channel not in result:
        names = sorted(set(result.channel_names) | set(result.state_names))
        close = options.close_matches(str(channel), names, n=3) if isinstance(channel, str) else []
        hint = f" (close: {', '.join(close)})" if close else ""
        options.fail(f.where, f.channel, channel, f"a channel of the result{hint}, e.g. {names[0]!r}"
                     if names else "a channel of the result")
    if np.asarray(result[channel]).ndim != 1:
        options.fail(f.where, f.channel, channel, "a channel with one value per time")
    return channel


def _writer(path: Path, fps: float, f: _Fields) -> Any:
    """PillowWriter for a GIF; FFMpegWriter for an MP4, or a clear error when ffmpeg is missing."""
    import matplotlib
    from matplotlib import animation

    if path.suffix.lower() == ".gif":
        from PIL import Image

        class _Compact(animation.PillowWriter):
            """PillowWriter keeping each frame as a 256-colour image (what a GIF stores): a third of the memory."""

            def grab_frame(self, **savefig_kwargs: Any) -> None:
                super().grab_frame(**savefig_kwargs)
                frames = self._frames  # type: ignore[attr-defined]  # PillowWriter's list, not in the stubs
                frames[-1] = frames[-1].convert("RGB").convert("P", palette=Image.Palette.ADAPTIVE)

        return _Compact(fps=fps)  # type: ignore[arg-type]  # stubs say int; a float fps works as given
    program = str(matplotlib.rcParams["animation.ffmpeg_path"])
    if shutil.which(program) is None:
        raise MissingDependencyError(
            f"{f.where}: {f.path}={str(path)!r}: writing an MP4 needs the program ffmpeg, which was not found "
            f"(matplotlib rcParams['animation.ffmpeg_path'] = {program!r}); install ffmpeg, or write a .gif "
            "(pillow, no external program needed).")
    # libx264 with yuv420p needs even width and height
    return animation.FFMpegWriter(fps=fps, codec="h264",  # type: ignore[arg-type]  # as above
                                  extra_args=["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"])


def _check_path(path: Any, f: _Fields) -> Path:
    from ..results.outputs import check_file

    what = "an animation file ending in .gif (or .mp4 when ffmpeg is installed)"
    if not isinstance(path, (str, os.PathLike)):
        options.fail(f.where, f.path, path, what)
    p = Path(path)
    if p.is_dir() or str(path) == "":  # check_file says so, with a file name to use
        check_file(p if str(path) else "", f"{f.where} {f.path}", what=what, example="run.gif")
    if p.suffix.lower() not in FORMATS:
        options.fail(f.where, f.path, str(path), what)
    return check_file(p, f"{f.where} {f.path}", what=what, example="run.gif")


def animate(result: Result, path: str | os.PathLike[str], *, fps: float = 25.0, window: Window = None,
            slow_motion: float | None = None, size: tuple[int, int] = (720, 450), channel: str | None = None,
            magnify: float | None = None, progress: bool = False) -> Path:
    """Write an animation of ``result``: the mechanism moving, its clearance joints magnified, a time cursor.

    Parameters
    ----------
    result : Result
        A run with its scene description (``result.parameters["scene"]``) and every body's x, y, phi.
    path : str or path-like
        ``*.gif`` (pillow) or ``*.mp4`` (needs the program ffmpeg); written atomically.
    fps : float
        Frames per second, in (0, 100].
    window : (t0, t1), optional
        Simulated time shown, s, inside the run with t0 < t1 (a None side: the run's start or end).
    slow_motion : float, optional
        How many times slower than real time the window plays (> 0); None: in :data:`DEFAULT_PLAY_TIME`.
        ``n_frames = max(2, round(D * slow_motion * fps))`` (:func:`frame_count`), at most :data:`MAX_FRAMES`.
    size : (int, int)
        Width and height, pixels, each in [160, 4000].
    channel : str, optional
        Channel of the time plot; None: the first driver's moment, else the first clearance joint's
        normal force, else the mechanical energy.
    magnify : float, optional
        Magnification (> 0) of a translational clearance joint's offsets in its panel; None: the
        magnified clearance spans a quarter of the slider width (a 1-2-5 number).
    progress : bool
        Show the frames rendered on stderr.

    Returns ``path`` (a Path). Raises SceneError for a bad option (named, with its value and what is
    allowed) or a result without scene description or body channels, MissingDependencyError for an MP4
    without ffmpeg, OutputError when ``path`` cannot be written (all before rendering).
    """
    return render(result, path, fps=fps, window=window, slow_motion=slow_motion, size=size, channel=channel,
                  magnify=magnify, progress=progress)


def render(result: Result, path: Any, *, fps: Any, window: Window, slow_motion: Any, size: Any,
           channel: Any, magnify: Any, progress: Any, fields: _Fields = _Fields()) -> Path:
    """:func:`animate` with the option names of the caller (``fields``) in its messages."""
    f = fields
    fps_v = options.number(fps, where=f.where, field=f.fps, low=0.0, high=MAX_FPS)
    t0, t1 = _window(result, window, f)
    duration = t1 - t0
    speed = (DEFAULT_PLAY_TIME / duration if slow_motion is None
             else options.number(slow_motion, where=f.where, field=f.slow_motion, low=0.0))
    width, height = _size(size, f)
    if magnify is not None:
        options.number(magnify, where=f.where, field=f.magnify, low=0.0)
    show = options.flag(progress, where=f.where, field=f.progress)
    n_frames = frame_count(duration, speed, fps_v)
    if n_frames > MAX_FRAMES:
        raise SceneError(f"{f.where}: {n_frames} frames (duration {duration:g} s x {f.slow_motion} {speed:g} x "
                         f"{f.fps} {fps_v:g}), must be at most {MAX_FRAMES}; shorten {f.window} or lower "
                         f"{f.slow_motion} or {f.fps}.")
    geo = scene_geometry(result, f.where)
    clearance = [j for j in geo.joints if j.kind in ("RevoluteClearance", "TranslationalClearance")]
    channel_v = _default_channel(result, geo, clearance) if channel is None else _check_channel(result, channel, f)
    target = _check_path(path, f)
    writer = _writer(target, fps_v, f)  # an MP4 without ffmpeg fails here, before any rendering

    import matplotlib
    import matplotlib.pyplot as plt

    times = frame_times(t0, t1, n_frames)
    sampler = Sampler(result, times, t0, t1)
    for body in geo.bodies:
        body_pose(sampler, body, geo, f.where)  # every body's channels exist, before a figure is made
    contact: dict[str, NDArray[np.float64]] = {}
    depth: dict[str, NDArray[np.float64]] = {}
    for j in clearance:
        contact[j.name], depth[j.name] = contact_state(sampler, j.name)
    shown = clearance[:MAX_INSETS]

    scale, unit = (1e3, "ms") if max(abs(t0), abs(t1)) < 1.0 else (1.0, "s")
    spacing = (t1 - t0) / (n_frames - 1) * scale
    decimals = min(9, max(0, math.ceil(-math.log10(spacing)))) + 1 if spacing > 0 else 3

    with matplotlib.rc_context({"font.size": float(np.clip(height / 55.0, 5.5, 11.0)), "savefig.bbox": None}):
        fig = plt.figure(figsize=(width / _DPI, height / _DPI), dpi=_DPI)
        try:
            updates = layout_frame(fig, result, geo, sampler, shown, contact, depth, magnify, channel_v, t0, t1,
                                   scale, unit, f.where)
            clock = fig.text(0.99, 0.985, "", ha="right", va="top", fontsize="small", family="monospace")
            fig.text(0.01, 0.985, style.caption(result), ha="left", va="top", fontsize="small")
            if len(clearance) > len(shown):
                fig.text(0.99, 0.01, f"{len(clearance) - len(shown)} more clearance joint(s) not shown",
                         ha="right", va="bottom", fontsize="x-small", color="0.4")
            _write(fig, writer, target, n_frames, updates, clock, times * scale, unit, decimals, show)
        finally:
            plt.close(fig)
    return target


def _write(fig: Figure, writer: Any, target: Path, n_frames: int, updates: Sequence[Callable[[int], None]],
           clock: Any, times: NDArray[np.float64], unit: str, decimals: int, show: bool) -> None:
    """Render every frame into a temporary file beside ``target``, renamed over it once complete
    (:func:`daeclear.results.outputs.atomic_file`; Ctrl-C waits while the file is finished)."""
    from ..results.outputs import atomic_file, deferred_sigint

    bar = Progress(n_frames, unit="frames", desc=f"animating {target.name}", enabled=show)
    try:
        with atomic_file(target, keep_suffix=True) as tmp:
            writer.setup(fig, str(tmp), dpi=_DPI)
            try:
                for k in range(n_frames):
                    for update in updates:
                        update(k)
                    clock.set_text(f"t = {times[k]:.{decimals}f} {unit}")
                    writer.grab_frame()
                    bar.update(k + 1)
            finally:
                bar.close()
            with deferred_sigint():
                writer.finish()
    except BaseException:
        proc = getattr(writer, "_proc", None)  # ffmpeg, when it was started
        if proc is not None and proc.poll() is None:
            proc.kill()
        raise
