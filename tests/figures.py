"""What a figure shows: the matplotlib figures a plotting function saved, and the pixels of a PNG.

:func:`saved_figures` keeps every matplotlib figure saved inside a ``with`` block (the files are
still written by matplotlib), so a test can check the data the figure draws: its axes, bars,
lines and limits. For pictures rendered with pyvista, :func:`read_png` and the pixel helpers
check what the image holds, region by region.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg
import numpy as np
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure


class SavedFigures(list):
    """Figures in the order they were saved, with the file each was saved to."""

    def __init__(self) -> None:
        super().__init__()
        self.paths: list[Path] = []

    def named(self, name: str) -> Figure:
        """The one figure saved to a file called ``name``."""
        (figure,) = [f for f, p in zip(self, self.paths, strict=True) if p.name == name]
        return figure


@contextmanager
def saved_figures() -> Iterator[SavedFigures]:
    """The matplotlib figures saved with ``Figure.savefig`` inside the block, in order."""
    figures = SavedFigures()
    savefig = Figure.savefig

    def keep(self: Figure, fname, *args, **kwargs):
        figures.append(self)
        figures.paths.append(Path(fname))
        return savefig(self, fname, *args, **kwargs)

    Figure.savefig = keep
    try:
        yield figures
    finally:
        Figure.savefig = savefig


def read_png(path: str | Path) -> np.ndarray:
    """RGB of a PNG file, float array of shape (height, width, 3) in [0, 1]."""
    image = mpimg.imread(Path(path), format="png")
    if image.dtype == np.uint8:
        image = image / 255.0
    return np.asarray(image[..., :3], dtype=np.float64)


def colour_mask(rgb: np.ndarray, colour: str | tuple[float, float, float], tol: float = 0.04):
    """Pixels within ``tol`` (per channel) of ``colour``, bool array of shape (height, width)."""
    return np.all(np.abs(rgb - np.asarray(to_rgb(colour))) <= tol, axis=-1)


def ink(rgb: np.ndarray, background: str = "white", tol: float = 0.04) -> np.ndarray:
    """Pixels that are not background, bool array of shape (height, width)."""
    return ~colour_mask(rgb, background, tol)


def distinct_colours(rgb: np.ndarray) -> int:
    """Number of distinct colours (8 bits per channel) in the image."""
    quantised = np.round(rgb.reshape(-1, 3) * 255.0).astype(np.int64)
    return int(np.unique(quantised[:, 0] * 65536 + quantised[:, 1] * 256 + quantised[:, 2]).size)


def bbox(mask: np.ndarray) -> tuple[int, int, int, int]:
    """(row_min, row_max, col_min, col_max) of the True pixels of a non-empty mask."""
    rows, cols = np.nonzero(mask)
    if rows.size == 0:
        raise AssertionError("no pixel of the kind looked for")
    return int(rows.min()), int(rows.max()), int(cols.min()), int(cols.max())
