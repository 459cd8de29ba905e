"""The one progress display of daeclear: runs, sweeps and animations all report through it.

On a terminal a tqdm bar; anywhere else (CI logs, pipes) plain lines, one at each tenth of the
total and at most one every ``interval`` seconds in between. Disabled, it prints nothing.

>>> import io
>>> out = io.StringIO()
>>> bar = Progress(4, unit="runs", desc="sweep", stream=out)
>>> for k in range(1, 5):
...     bar.update(k, f"run {k}")
>>> bar.close()
>>> len(out.getvalue().splitlines())
4
"""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO

PLAIN_STEPS = 10  # plain mode: a line at each 1/PLAIN_STEPS of the total ...
PLAIN_INTERVAL = 30.0  # ... and at least every PLAIN_INTERVAL seconds
TTY_STEPS = 1000  # terminal mode: redrawn at most once per 1/TTY_STEPS of the total


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


def is_terminal(stream: Any) -> bool:
    """Whether ``stream`` is an interactive terminal (False when it cannot say)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):  # no isatty, or a closed file
        return False


class Progress:
    """Progress of ``total`` units of work (seconds simulated, runs, frames) on ``stream`` (stderr);
    :meth:`update` is cheap when nothing is due (a solver calls it every step)."""

    def __init__(self, total: float, *, unit: str = "", desc: str = "", enabled: bool = True,
                 stream: TextIO | None = None, interval: float = PLAIN_INTERVAL) -> None:
        self.total, self.unit, self.desc, self.enabled = total, unit, desc, enabled
        self.stream: Any = stream if stream is not None else sys.stderr
        self.interval = interval
        self.done: float = 0
        self.note = ""
        self.closed = not enabled
        self.start = time.perf_counter()
        self._next = 0.0  # plain: the fraction of the total at which the next line is due
        self._last_line = self.start
        self._step = (total / TTY_STEPS) if total > 0 else 0.0  # terminal: the smallest change drawn
        self._drawn: float = -1.0
        self._shown: tuple[float, str] | None = None  # plain: the last line's work and note
        self.bar: Any = _bar(total, unit, desc, self.stream) if enabled and is_terminal(self.stream) else None

    @property
    def mode(self) -> str:
        """``"off"``, ``"tty"`` (a tqdm bar) or ``"plain"`` (rate-limited lines)."""
        return "off" if not self.enabled else "tty" if self.bar is not None else "plain"

    def fraction(self, done: float) -> float:
        """The share of the total that ``done`` is, in [0, 1] (1 for an empty total)."""
        return min(1.0, max(0.0, done / self.total)) if self.total > 0 else 1.0

    def update(self, done: float, note: str = "") -> None:
        """Report ``done`` units of work done so far, with a short ``note``."""
        if self.closed:
            return
        self.done, self.note = done, note
        if self.bar is not None:
            if done - self._drawn >= self._step:
                self._drawn = done
                self.bar.set_postfix_str(note, refresh=False)
                self.bar.update(done - self.bar.n)
            return
        frac = self.fraction(done)
        now = time.perf_counter()
        if frac >= self._next or now - self._last_line >= self.interval:
            self._line(done, note, now)

    def close(self, note: str | None = None) -> None:
        """End the display: the final state (and ``note``, else the last one) on its own line."""
        if self.closed:
            return
        self.closed = True
        note = self.note if note is None else note
        if self.bar is not None:
            self.bar.set_postfix_str(note, refresh=False)
            self.bar.update(self.done - self.bar.n)
            self.bar.close()
        elif self._shown != (self.done, note):
            self._line(self.done, note, time.perf_counter())

    def _line(self, done: float, note: str, now: float) -> None:
        frac = self.fraction(done)
        self._next = (int(frac * PLAIN_STEPS) + 1) / PLAIN_STEPS
        self._last_line = now
        self._shown = (done, note)
        elapsed = now - self.start
        left = f", ~{_clock(elapsed / frac * (1 - frac))} left" if 0 < frac < 1 else ""
        head = f"{self.desc}: " if self.desc else ""
        unit = f" {self.unit}" if self.unit else ""
        text = (f"  {head}{done:.6g}/{self.total:.6g}{unit}  {100 * frac:5.1f} %"
                f" | {_clock(elapsed)} elapsed{left}" + (f" | {note}" if note else ""))
        self.stream.write(text + "\n")
        self.stream.flush()


def _bar(total: float, unit: str, desc: str, stream: Any) -> Any:
    """A tqdm bar on ``stream``, without tqdm's monitor thread (sweeps fork worker processes)."""
    from tqdm import tqdm

    class Bar(tqdm):
        monitor_interval = 0

    spec = "{n:.6g}/{total:.6g}" + (f" {unit}" if unit else "")
    return Bar(total=total, desc=desc or None, file=stream, leave=True, dynamic_ncols=True,
               bar_format="{l_bar}{bar}| " + spec + " [{elapsed}<{remaining}{postfix}]")
