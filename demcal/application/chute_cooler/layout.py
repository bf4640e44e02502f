"""The set-up record of the chute-cooler deck and where its boxes are at a given time.

:func:`demcal.application.chute_cooler.setup.chute_cooler_setup` computes the record; the deck,
the meshes and the segregation analysis read it (also back from ``case.json``). Coordinates as
in :mod:`demcal.application.chute_cooler.setup`: x the direction of box travel, y across the
row, z up, box floors at ``z = 0``. SI units throughout.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from demcal.particles.run_setup import RunSetup

__all__ = ["ChuteCoolerSetup"]


@dataclass(frozen=True, kw_only=True)
class ChuteCoolerSetup(RunSetup):
    """Every derived number of the chute-cooler deck (SI units); the run fields are those of
    :class:`~demcal.particles.run_setup.RunSetup`.

    Attributes
    ----------
    radii, mass_fractions : tuple of float
        Size classes (m) and their mass fractions (-).
    r_min, r_max : float
        Smallest and largest particle radius, m.
    particle_mass : float
        Expected (number-weighted) particle mass, kg.
    n_boxes : int
        Boxes in the row.
    box_length, box_width, box_height : float
        L (along x), W (along y), H (partition height), m.
    rim_height : float
        Height of the row's side walls, m.
    lead_wall_height : float
        Height of the leading wall of box 1, m (the rim height, or less where the wall starts
        under the chute).
    analysed_box : int
        The box whose layers are analysed (1 = leading box).
    hole_size, hole_pitch : float
        Side and pitch of the square floor holes, m (0 size: closed floor).
    holes_per_box : tuple of int
        Holes along x and y in one floor.
    open_area_fraction : float
        Hole area over floor area, -.
    box_speed : float
        Speed of the row along +x, m/s.
    box_front_x0 : float
        Initial x of the leading wall of box 1, m.
    chute_angle : float
        Inclination of the chute, degrees.
    chute_edge, chute_top : tuple of float
        (x, z) of the discharge edge and of the upper end of the chute floor, m.
    chute_y : tuple of float
        Inner width of the chute, (y0, y1), m.
    chute_wall_height : float
        Height of the chute's side walls and back wall above its floor, m.
    mass_rate, particle_rate : float
        Feed, kg/s and 1/s.
    feed_lo, feed_hi : tuple of float
        Corners of the insertion block, m.
    feed_velocity : tuple of float
        Insertion velocity, m/s.
    insert_every : int
        Steps between insertion events.
    exit_speed, landing_x, arrival_time : float
        Estimated stream speed at the discharge edge (m/s), landing x at the partition tops
        (m) and time for the first particles to reach the floor (s).
    travel : float
        Distance the row moves in stage 1, m.
    startup_steps, travel_steps : int
        Steps of stage 0 (boxes at rest) and stage 1 (boxes moving).
    dump_every, vtk_every : int
        Output intervals in steps (text dump for the analysis, VTK dump).
    particles_per_box : float
        Particles in one box filled to H at the bulk density estimate, -.
    expected_particles : float
        Particles fed over the whole run (an upper bound of the particle count), -.
    n_triangles : dict of str to int
        Triangles of the chute and box meshes.
    """

    radii: tuple[float, ...]
    mass_fractions: tuple[float, ...]
    r_min: float
    r_max: float
    particle_mass: float
    n_boxes: int
    box_length: float
    box_width: float
    box_height: float
    rim_height: float
    lead_wall_height: float
    analysed_box: int
    hole_size: float
    hole_pitch: float
    holes_per_box: tuple[int, int]
    open_area_fraction: float
    box_speed: float
    box_front_x0: float
    chute_angle: float
    chute_edge: tuple[float, float]
    chute_top: tuple[float, float]
    chute_y: tuple[float, float]
    chute_wall_height: float
    mass_rate: float
    particle_rate: float
    feed_lo: tuple[float, float, float]
    feed_hi: tuple[float, float, float]
    feed_velocity: tuple[float, float, float]
    insert_every: int
    exit_speed: float
    landing_x: float
    arrival_time: float
    travel: float
    startup_steps: int
    travel_steps: int
    dump_every: int
    vtk_every: int
    particles_per_box: float
    expected_particles: float
    n_triangles: dict[str, int] = field(default_factory=dict)

    @property
    def startup_time(self) -> float:
        """Duration of stage 0 (boxes at rest), s."""
        return self.startup_steps * self.timestep

    def row_offset(self, time: float | np.ndarray) -> float | np.ndarray:
        """Distance the row has moved at ``time`` (s) since the start of the run, m."""
        t = np.maximum(np.asarray(time, dtype=float) - self.startup_time, 0.0)
        out = self.box_speed * t
        return float(out) if out.ndim == 0 else out

    def box_bounds(self, box: int, time: float) -> tuple[float, float, float, float, float, float]:
        """Interior of box ``box`` (1 = leading) at ``time`` (s): x0, x1, y0, y1, z0, z1 in m."""
        if not 1 <= box <= self.n_boxes:
            raise ValueError(f"box must be in 1..{self.n_boxes}, got {box}")
        front = self.box_front_x0 - (box - 1) * self.box_length + float(self.row_offset(time))
        return (front - self.box_length, front, 0.0, self.box_width, 0.0, self.box_height)

    @classmethod
    def from_dict(
        cls, record: Mapping[str, Any], source: str = "set-up record"
    ) -> ChuteCoolerSetup:
        """Rebuild the set-up from :meth:`as_dict` output (e.g. read back from ``case.json``).

        Raises
        ------
        KeyError
            A field is missing; the message names ``source`` and the field.
        """
        values: dict[str, Any] = {}
        for f in fields(cls):
            if f.name not in record:
                raise KeyError(f"{source}: missing field {f.name!r}")
            value = record[f.name]
            values[f.name] = tuple(value) if isinstance(value, list) else value
        return cls(**values)
