"""Seeded mutations of rendered decks for fuzzing the engine.

The tiny profile's decks (shear cell, angle of repose, chute cooler) are rendered once, with
their meshes, into a work directory. Each fuzz case copies one of them into its own directory,
applies one to three random mutations to the deck text (dropped, duplicated and swapped lines;
a number replaced by 0, its negative, +-1e300, nan, inf or text; a truncated line; a random
token inserted) and runs the engine on it with a time limit.

Every ``run N`` whose step count is a plain integer is then replaced by ``run min(N,
max_steps)`` (also for lines a mutation duplicated), so that a mutated deck that is still valid
finishes in a fraction of a second; a count in any other form (``1e300``, ``nan``, ``-5``) is
left for the engine to judge.
"""

from __future__ import annotations

import random
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

NUMBER = re.compile(r"(?<![\w.$\[{])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.\]}])")
RUN_LINE = re.compile(r"^(\s*run\s+)(\d+)(?=\s|$)")

#: What a number may be replaced by.
NUMBER_REPLACEMENTS = (
    "0",
    "-{}",
    "1e300",
    "-1e300",
    "1e200",
    "1e20",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "abc",
    "2147483648",
    "9223372036854775807",
)
#: Tokens a mutation may insert besides the deck's own words; no `jump`/`next`/`label`,
#: which could loop a valid deck for ever.
EXTRA_TOKENS = (
    "0",
    "-1",
    "1e300",
    "nan",
    "inf",
    "-inf",
    "&",
    "#",
    "$",
    "${",
    "$(",
    ")",
    "'",
    '"',
    '"""',
    "*",
    "v_",
    "f_",
    "c_",
    "all",
    "NULL",
    "yes",
    "no",
    "upto",
    "every",
    "region",
    "type",
    "2147483648",
    "9223372036854775808",
    "-2147483649",
    "1e19",
    "0x10",
    "",
)


@dataclass
class BaseDeck:
    """One rendered deck: its case directory (deck, meshes, other inputs) and deck file name."""

    name: str
    directory: Path
    deck: str

    def text(self) -> str:
        """The deck text."""
        return (self.directory / self.deck).read_text()


@dataclass
class FuzzCase:
    """One mutated deck."""

    index: int
    base: str
    mutations: list[str]
    text: str


def _numbers(line: str) -> list[re.Match[str]]:
    return list(NUMBER.finditer(line))


def mutate(text: str, rng: random.Random, vocabulary: Sequence[str]) -> tuple[str, str]:
    """Apply one random mutation to a deck text.

    Parameters
    ----------
    text : str
        Deck text.
    rng : random.Random
        Source of randomness.
    vocabulary : sequence of str
        Tokens a ``token`` mutation may insert.

    Returns
    -------
    (str, str)
        The mutated text and a description of the mutation (1-based line numbers of the text
        it was applied to).
    """
    lines = text.split("\n")
    n = len(lines)
    i = rng.randrange(n)
    op = rng.choice(("drop", "dup", "swap", "number", "number", "number", "truncate", "token"))
    if op == "number":
        # A line that has numbers, if one is found within a few tries.
        for _ in range(20):
            if _numbers(lines[i]) and not lines[i].lstrip().startswith("#"):
                break
            i = rng.randrange(n)
        found = _numbers(lines[i])
        if not found:
            op = "token"
        else:
            m = rng.choice(found)
            new = rng.choice(NUMBER_REPLACEMENTS)
            if new == "-{}":
                new = m.group()[1:] if m.group().startswith("-") else "-" + m.group()
            lines[i] = lines[i][: m.start()] + new + lines[i][m.end() :]
            return "\n".join(lines), f"line {i + 1}: number {m.group()!r} -> {new!r}"
    if op == "drop":
        del lines[i]
        return "\n".join(lines), f"line {i + 1}: dropped"
    if op == "dup":
        lines.insert(i, lines[i])
        return "\n".join(lines), f"line {i + 1}: duplicated"
    if op == "swap":
        j = rng.randrange(n) if rng.random() < 0.5 else min(n - 1, i + 1)
        lines[i], lines[j] = lines[j], lines[i]
        return "\n".join(lines), f"lines {i + 1} and {j + 1}: swapped"
    if op == "truncate":
        cut = rng.randrange(len(lines[i]) + 1)
        lines[i] = lines[i][:cut]
        return "\n".join(lines), f"line {i + 1}: truncated to {cut} characters"
    words = lines[i].split(" ")
    token = rng.choice(vocabulary) if rng.random() < 0.6 else rng.choice(EXTRA_TOKENS)
    at = rng.randrange(len(words) + 1)
    words.insert(at, token)
    lines[i] = " ".join(words)
    return "\n".join(lines), f"line {i + 1}: token {token!r} inserted as word {at + 1}"


def cap_runs(text: str, max_steps: int) -> str:
    """Replace every ``run N`` with a plain integer N by ``run min(N, max_steps)``."""

    def cap(line: str) -> str:
        m = RUN_LINE.match(line)
        if not m:
            return line
        return m.group(1) + str(min(int(m.group(2)), max_steps)) + line[m.end() :]

    return "\n".join(cap(line) for line in text.split("\n"))


def make_cases(bases: Sequence[BaseDeck], cases: int, seed: int, max_steps: int) -> list[FuzzCase]:
    """Generate ``cases`` seeded mutations of the base decks (round robin over the decks).

    Parameters
    ----------
    bases : sequence of BaseDeck
        Rendered decks.
    cases : int
        How many mutated decks.
    seed : int
        Seed; the same seed gives the same cases.
    max_steps : int
        Cap on the step count of every ``run`` (see :func:`cap_runs`).

    Returns
    -------
    list of FuzzCase
    """
    rng = random.Random(seed)
    texts = {b.name: b.text() for b in bases}
    vocabulary = sorted({w for t in texts.values() for w in t.split() if not w.startswith("#")})
    out = []
    for index in range(cases):
        base = bases[index % len(bases)]
        text = texts[base.name]
        mutations = []
        for _ in range(rng.choice((1, 1, 2, 3))):
            text, what = mutate(text, rng, vocabulary)
            mutations.append(what)
        out.append(FuzzCase(index, base.name, mutations, cap_runs(text, max_steps)))
    return out
