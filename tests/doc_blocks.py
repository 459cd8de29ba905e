"""The fenced code blocks of README.md and docs/*.md, and the shell commands in them (tests/test_docs.py).

A block is a Markdown fence with a language: ``python`` and ``bash`` run, ``console`` runs its ``$ ``
commands and compares what they print with the lines under them, ``toml`` is parsed, ``text`` is
output or a drawing. A block whose first line is a comment ``# slow: <reason>`` or
``# placeholder: <reason>`` is marked: a reader sees the marker, and the docs test runs a slow
block shortened and checks a placeholder block without running it.
"""

from __future__ import annotations

import re
import shlex
import textwrap
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LANGUAGES = ("python", "bash", "console", "toml", "text")
MARKERS = ("slow", "placeholder")
FENCE = re.compile(r"^(?P<indent>\s*)```(?P<lang>\S*)\s*$")
MARKER = re.compile(r"^#\s*(?P<kind>[a-z]+):\s*(?P<reason>.*)$")


@dataclass(frozen=True)
class Block:
    """One fenced block: where it is, its language, its text (dedented) and its marker."""

    path: Path  # relative to the repository
    line: int  # line of the opening fence, from 1
    lang: str
    text: str
    marker: str = ""  # "", "slow" or "placeholder"
    reason: str = ""

    @property
    def id(self) -> str:
        return f"{self.path.as_posix()}:{self.line}"


@dataclass(frozen=True)
class Command:
    """One shell command: its environment assignments and its words (``a && b`` is two commands)."""

    env: dict[str, str]
    argv: list[str]
    text: str  # the logical line it came from


def documents() -> list[Path]:
    """README.md and docs/*.md, relative to the repository."""
    return [Path("README.md")] + sorted(p.relative_to(ROOT) for p in (ROOT / "docs").glob("*.md"))


def blocks(path: Path) -> list[Block]:
    """The fenced blocks of one document, in order."""
    lines = (ROOT / path).read_text().split("\n")
    out: list[Block] = []
    i = 0
    while i < len(lines):
        match = FENCE.match(lines[i])
        if match is None:
            i += 1
            continue
        end = i + 1
        while end < len(lines) and not re.match(r"^\s*```\s*$", lines[end]):
            end += 1
        if end == len(lines):
            raise ValueError(f"{path}:{i + 1}: a fence that is never closed")
        text = textwrap.dedent("\n".join(lines[i + 1:end])) + "\n"
        first = text.split("\n", 1)[0]
        marker = MARKER.match(first) if match["lang"] in ("python", "bash") else None
        kind, reason = ("", "")
        if marker is not None and marker["kind"] in MARKERS:
            kind, reason = marker["kind"], marker["reason"].strip()
        out.append(Block(path, i + 1, match["lang"], text, kind, reason))
        i = end + 1
    return out


def all_blocks() -> list[Block]:
    return [block for path in documents() for block in blocks(path)]


def logical_lines(text: str) -> list[str]:
    """The lines of a shell text with backslash continuations joined, blank and comment lines dropped."""
    out: list[str] = []
    current = ""
    for raw in text.split("\n"):
        if raw.rstrip().endswith("\\"):
            current += raw.rstrip()[:-1] + " "
            continue
        line = (current + raw).strip()
        current = ""
        if line and not line.startswith("#"):
            out.append(line)
    return out


def commands(line: str) -> list[Command]:
    """The commands of one logical shell line: ``&&`` separates them, ``NAME=value`` words before the
    program are its environment, a ``#`` word starts a comment."""
    words = shlex.split(line, comments=True)
    out: list[Command] = []
    while words:
        end = words.index("&&") if "&&" in words else len(words)
        part, words = words[:end], words[end + 1:]
        env: dict[str, str] = {}
        while part and re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", part[0]):
            name, value = part.pop(0).split("=", 1)
            env[name] = value
        if not part:
            raise ValueError(f"no command in {line!r}")
        out.append(Command(env, part, line))
    return out


def console_session(text: str) -> list[tuple[str, str]]:
    """(command, expected output) pairs of a console block: a ``$ `` line, then what it prints."""
    pairs: list[tuple[str, list[str]]] = []
    for line in text.rstrip("\n").split("\n"):
        if line.startswith("$ "):
            pairs.append((line[2:], []))
        elif not pairs:
            raise ValueError(f"console block starts without a '$ ' command: {line!r}")
        else:
            pairs[-1][1].append(line)
    return [(command, "\n".join(output)) for command, output in pairs]
