"""Reader of legacy VTK particle dumps (``dump custom/vtk``), through :func:`pyvista.read`."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from demcal.engine_io.output_errors import EngineOutputError, require_columns


@dataclass(frozen=True)
class VtkParticles:
    """Particle positions and per-particle arrays of one VTK dump.

    Attributes
    ----------
    points : numpy.ndarray
        Shape (n, 3), particle centres (m).
    arrays : dict of str to numpy.ndarray
        Point-data arrays by name, each of shape (n,) or (n, k) (SI units as dumped).
    """

    points: np.ndarray
    arrays: dict[str, np.ndarray]


def read_vtk_particles(
    path: str | Path,
    arrays: Sequence[str] | None = None,
) -> VtkParticles:
    """Read a particle dump written by ``dump custom/vtk`` (legacy ``.vtk`` or XML) with pyvista.

    Parameters
    ----------
    path : str or Path
        The VTK file.
    arrays : sequence of str, optional
        Point-data arrays the caller needs (e.g. ``["radius"]``).

    Returns
    -------
    VtkParticles
        Points of shape (n, 3) and the point-data arrays.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    EngineOutputError
        The file cannot be parsed or holds no points.
    MissingColumnError
        An array in ``arrays`` is absent.
    """
    import pyvista

    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"{p}: no such VTK file")
    try:
        mesh = pyvista.read(str(p))
    except Exception as exc:  # VTK raises assorted types for unreadable files
        raise EngineOutputError(p, f"cannot read VTK data ({exc})") from exc
    if isinstance(mesh, pyvista.MultiBlock):
        blocks = [b for b in mesh if b is not None and b.n_points > 0]
        if len(blocks) != 1:
            raise EngineOutputError(p, f"expected one particle block, found {len(blocks)}")
        mesh = blocks[0]
    points = np.asarray(mesh.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[0] == 0:
        raise EngineOutputError(p, "no points in VTK file (empty or unparsable)")
    data = {name: np.asarray(mesh.point_data[name]) for name in list(mesh.point_data.keys())}
    require_columns(list(data), arrays, p)
    return VtkParticles(points=points, arrays=data)
