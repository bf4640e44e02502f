"""Derived quantities of the sinter chute-cooler application (paper Figs. 10-11).

Sinter fines slide down an inclined chute and fall into a row of open-top boxes with
perforated floors that move underneath. The question is whether the coarse particles end up at
the bottom of the boxes, where the cooling air enters. Everything the deck needs is computed
here from the configuration section ``application``, the ``material`` section and the contact
parameters; the template only formats the numbers. SI units throughout.

Coordinates
-----------
x is the direction of box travel, y across the row, z up. The boxes have their floors at
``z = 0`` and span ``0 <= y <= W``. The chute's lower (discharge) edge is the line
``x = 0, z = H + chute_drop``; the chute rises towards +x at ``chute_angle``, so material flows
against the box motion (towards -x), onto the upstream slope of the heap it builds.

Boxes
-----
``n_boxes`` boxes of length ``L``, width ``W`` and height ``H`` sit side by side; box 1 leads
(largest x). The partitions and the back wall are ``H`` high, so they pass under the chute's
discharge edge; the row's two side walls reach ``rim_height * H`` and keep the bed heaped above
the partitions on the row. The leading wall is as high as the side walls where it can be (it
starts under the chute and must stay below the chute floor), so the start-up heap builds
against it. The chute is narrower than the row by ``0.2 d_min`` on each side (a gap no
particle fits through), so its side walls run inside the row's side walls and may reach below
their top.

Box ``analysed_box`` is analysed: its interior ``0 <= z <= H`` is divided into the three layers;
material above ``H`` is the continuously supplied heap and is not analysed. Box 1 is filled by
the start-up heap, which forms against the leading wall with the stream landing on it from the
start; box 2 and later ones pass under a developed heap, as every box does in continuous
operation, so ``analysed_box = 2`` is "the first box filled by the chute" at steady state.

The perforated floor is a triangulated plate with a square grid of square holes (side
``hole_size * d_min``, pitch ``hole_pitch * d_min``, ``d_min`` the smallest particle diameter).
The holes are smaller than every particle, as in a real cooler grate: air would pass, particles
do not. ``hole_size = 0`` gives a closed floor. The grid cells keep the triangles' aspect ratio
near one (no slivers).

Feed and timing
---------------
The mass rate fills the moving row to ``fill_ratio`` box heights at the bulk density estimate:
``Q = fill_ratio * rho_b * W * H * v_box``. Particles are inserted (``fix insert/rate/region``)
in a block above the upper end of the chute with a velocity ``feed_speed`` down the slope.
The block is ``feed_height`` largest diameters high and long enough that one insertion event
fills at most ``insertion_fraction`` of it; events are spaced by the time a particle needs to
fall through the block, so each batch has left before the next is placed.

Where the stream lands is estimated with a sliding particle (``a = g (sin(theta) - mu_w
cos(theta))`` along the chute from the middle of the feed block, then a free fall to the
partition tops). The leading wall of box 1 stands ``front_clearance`` largest diameters ahead of
the discharge edge, so the whole stream enters the row. Stage 0 keeps the boxes at rest until
the stream has reached the floor and has filled box 1 between the landing point and the
leading wall (at the feed rate, the time to deposit that stretch of bed); stage 1 moves them at
``v_box`` until the back wall of the analysed box has passed the landing point and the row has
travelled a further ``run_after_fill * L``, so that box no longer receives material and its
layers reach a steady state. Particles that leave the simulation box (spilling off the row)
are deleted.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import partial
from typing import Any

from demcal.application.chute_cooler.layout import ChuteCoolerSetup
from demcal.application.chute_cooler.meshes import box_row_triangles, chute_triangles, hole_grid
from demcal.core import config_values
from demcal.core.config_values import SetupError
from demcal.core.parameters import GRAVITY
from demcal.particles.material import MaterialSetup
from demcal.particles.run_setup import insertion_seeds, steps_for
from demcal.particles.size_distribution import SizeDistribution

__all__ = ["chute_cooler_setup", "stream_estimate"]

_SECTION = "application"

# Configuration access with errors naming application.<key>.
_positive = partial(config_values.positive, where=_SECTION)
_in_range = partial(config_values.in_range, where=_SECTION)
_count = partial(config_values.count, where=_SECTION)


def stream_estimate(
    start_speed: float,
    slide_distance: float,
    angle_deg: float,
    wall_friction: float,
    drop: float,
) -> tuple[float, float, float, float]:
    """Speed at the discharge edge, horizontal throw, slide and fall time of a sliding particle.

    The particle slides down an incline of ``angle_deg`` with Coulomb friction
    ``wall_friction`` (``a = g (sin(theta) - mu cos(theta))``), leaves the edge along the
    slope and falls freely through ``drop``.

    Parameters
    ----------
    start_speed : float
        Speed along the slope at the start, m/s (>= 0).
    slide_distance : float
        Distance along the slope to the edge, m (>= 0).
    angle_deg : float
        Inclination, degrees.
    wall_friction : float
        Sliding friction coefficient with the chute, -.
    drop : float
        Height fallen after the edge, m (>= 0).

    Returns
    -------
    exit_speed : float
        m/s.
    throw : float
        Horizontal distance travelled during the fall, m.
    slide_time, fall_time : float
        s.

    Raises
    ------
    SetupError
        The chute is too flat for the friction (the particle would not slide).
    """
    theta = math.radians(angle_deg)
    accel = GRAVITY * (math.sin(theta) - wall_friction * math.cos(theta))
    if not accel > 0.0:
        raise SetupError(
            f"configuration: '{_SECTION}.chute_angle' = {angle_deg:g} deg is too flat for the wall "
            f"friction {wall_friction:g} (tan(angle) must exceed it)"
        )
    exit_speed = math.sqrt(start_speed**2 + 2.0 * accel * slide_distance)
    slide_time = (exit_speed - start_speed) / accel
    vz = exit_speed * math.sin(theta)
    fall_time = (-vz + math.sqrt(vz * vz + 2.0 * GRAVITY * drop)) / GRAVITY
    throw = exit_speed * math.cos(theta) * fall_time
    return exit_speed, throw, slide_time, fall_time


def chute_cooler_setup(
    section: Mapping[str, Any],
    dist: SizeDistribution,
    material: MaterialSetup,
    bulk_density: float | None = None,
    seed: int = 0,
    skin_factor: float = 1.0,
) -> ChuteCoolerSetup:
    """Derived quantities of the chute-cooler case.

    Parameters
    ----------
    section : mapping
        Configuration section ``application``.
    dist : SizeDistribution
        Particle sizes (the sinter fines of the application).
    material : MaterialSetup
        Material of the case (density, wall friction, time step).
    bulk_density : float, optional
        Bulk density for the feed rate, kg/m^3; default ``application.bulk_density``.
    seed : int
        Configuration seed (insertion randomness).
    skin_factor : float
        Neighbour skin in units of the smallest particle radius.

    Returns
    -------
    ChuteCoolerSetup

    Raises
    ------
    SetupError
        A setting that cannot work; the message names the configuration key.
    KeyError
        A missing configuration key.
    """
    r_min, r_max = dist.min_radius, dist.max_radius
    d_min, d_max = 2.0 * r_min, 2.0 * r_max
    n_boxes = _count(section, "n_boxes", 1)
    L = _positive(section, "box_length")
    W = _positive(section, "box_width")
    H = _positive(section, "box_height")
    for key, value in (("box_length", L), ("box_width", W), ("box_height", H)):
        if value < 3.0 * d_max:
            raise SetupError(
                f"configuration: '{_SECTION}.{key}' = {value:g} m is below three largest particle "
                f"diameters ({3.0 * d_max:g} m)"
            )
    fill_ratio = _positive(section, "fill_ratio")
    rim = _positive(section, "rim_height")
    if rim < fill_ratio:
        raise SetupError(
            f"configuration: '{_SECTION}.rim_height' ({rim:g}) must be >= "
            f"'{_SECTION}.fill_ratio' ({fill_ratio:g}) so the bed stays between the side walls"
        )
    hole_rel = _in_range(section, "hole_size", 0.0, 0.999)
    pitch_rel = _positive(section, "hole_pitch")
    if hole_rel > 0.0 and not pitch_rel > hole_rel:
        raise SetupError(
            f"configuration: '{_SECTION}.hole_pitch' ({pitch_rel:g}) must exceed "
            f"'{_SECTION}.hole_size' ({hole_rel:g})"
        )
    hole, pitch = hole_rel * d_min, pitch_rel * d_min
    n_hx = len(hole_grid(L, pitch, hole)) // 2 - 1
    n_hy = len(hole_grid(W, pitch, hole)) // 2 - 1
    open_fraction = n_hx * n_hy * hole * hole / (L * W)

    v_box = _positive(section, "box_speed")
    rho_b = float(bulk_density) if bulk_density is not None else _positive(section, "bulk_density")
    if not rho_b < material.density:
        raise SetupError(
            f"bulk density {rho_b:g} kg/m^3 must be below the particle density "
            f"{material.density:g} kg/m^3"
        )
    if fill_ratio < 1.0:
        raise SetupError(
            f"configuration: '{_SECTION}.fill_ratio' = {fill_ratio:g} < 1: the boxes cannot be "
            "filled"
        )
    after = _in_range(section, "run_after_fill", 0.0, 100.0)
    analysed = _count(section, "analysed_box", 1)
    if analysed > n_boxes:
        raise SetupError(
            f"configuration: '{_SECTION}.analysed_box' = {analysed} exceeds "
            f"'{_SECTION}.n_boxes' = {n_boxes}"
        )

    # feed
    mass_rate = fill_ratio * rho_b * W * H * v_box
    particle_mass = material.density * dist.mean_particle_volume
    particle_rate = mass_rate / particle_mass
    angle = _in_range(section, "chute_angle", 1.0, 89.0)
    theta = math.radians(angle)
    chute_length = _positive(section, "chute_length")
    drop = _positive(section, "chute_drop")
    if drop < d_max:
        raise SetupError(
            f"configuration: '{_SECTION}.chute_drop' = {drop:g} m must be at least one largest "
            f"particle diameter ({d_max:g} m), so the partitions pass under the chute"
        )
    chute_wall = _positive(section, "chute_wall_height")
    feed_speed = _in_range(section, "feed_speed", 0.0, 1e3)
    feed_height = _positive(section, "feed_height") * d_max
    phi_ins = _in_range(section, "insertion_fraction", 1e-3, 0.5)
    if chute_wall < feed_height + d_max:
        raise SetupError(
            f"configuration: '{_SECTION}.chute_wall_height' = {chute_wall:g} m must exceed the "
            f"feed block height plus a particle diameter ({feed_height + d_max:g} m)"
        )

    rim_top = rim * H
    z_edge = H + drop
    chute_y = (0.2 * d_min, W - 0.2 * d_min)
    x_top = chute_length * math.cos(theta)
    z_top = z_edge + chute_length * math.sin(theta)
    # events spaced by the time to fall through the block from rest plus the initial speed
    vz0 = feed_speed * math.sin(theta)
    event_time = (-vz0 + math.sqrt(vz0 * vz0 + 2.0 * GRAVITY * feed_height)) / GRAVITY
    dt = material.timestep
    insert_every = steps_for(event_time, dt)
    event_time = insert_every * dt
    per_event_solid = mass_rate * event_time / material.density
    gap = 0.05 * r_max
    feed_width = chute_y[1] - chute_y[0] - 2.0 * gap
    feed_length = per_event_solid / (phi_ins * feed_width * feed_height) + d_max
    if feed_length > 0.8 * x_top:
        raise SetupError(
            f"configuration: the feed block ({feed_length:g} m long) does not fit on the chute "
            f"(horizontal span {x_top:g} m); lengthen '{_SECTION}.chute_length' or raise "
            f"'{_SECTION}.insertion_fraction'"
        )
    feed_x1 = x_top - gap
    feed_x0 = feed_x1 - feed_length
    feed_z0 = z_top + gap
    feed_z1 = feed_z0 + feed_height
    feed_velocity = (-feed_speed * math.cos(theta), 0.0, -feed_speed * math.sin(theta))

    # stream estimate from the middle of the feed block
    slide = (0.5 * (feed_x0 + feed_x1)) / math.cos(theta)
    wall_friction = material.wall_friction
    exit_speed, throw, slide_time, _ = stream_estimate(
        feed_speed, slide, angle, wall_friction, z_edge - H
    )
    _, _, _, floor_fall = stream_estimate(feed_speed, slide, angle, wall_friction, z_edge)
    # from mid-height of the block down to the chute floor below the block's middle
    drop_to_chute = (x_top - 0.5 * (feed_x0 + feed_x1)) * math.tan(theta) + gap + 0.5 * feed_height
    insert_fall = (-vz0 + math.sqrt(vz0 * vz0 + 2.0 * GRAVITY * drop_to_chute)) / GRAVITY
    arrival_time = insert_fall + slide_time + floor_fall
    landing_x = -throw
    # the leading wall stands ahead of the discharge edge, so the whole stream enters the row
    box_front_x0 = _positive(section, "front_clearance") * d_max
    prefill = box_front_x0 - landing_x
    if not prefill < L:
        raise SetupError(
            f"configuration: '{_SECTION}.box_length' = {L:g} m is shorter than the distance "
            f"{prefill:g} m from the leading wall to where the stream lands"
        )
    # as high as the side walls, but below the chute floor it starts under and moves away from
    lead_wall = min(rim_top, z_edge + box_front_x0 * math.tan(theta) - r_max)
    # stage 0 lasts until the stream has arrived and filled box 1 ahead of the landing point
    startup_time = arrival_time + prefill / (fill_ratio * v_box)
    travel = analysed * L - prefill + after * L
    startup_steps = steps_for(startup_time, dt)
    n_snap = _count(section, "n_snapshots", 10)
    n_vtk = _count(section, "n_vtk", 1)
    travel_steps_min = steps_for(travel / v_box, dt)
    total_min = startup_steps + travel_steps_min
    dump_every = max(1, math.ceil(total_min / n_snap))
    vtk_every = dump_every * max(1, math.ceil(n_snap / n_vtk))
    # whole multiples, so the last snapshot of both dumps is the end of the run
    total = math.ceil(total_min / vtk_every) * vtk_every
    travel_steps = total - startup_steps
    travel = v_box * travel_steps * dt

    back_x0 = box_front_x0 - n_boxes * L
    # at the end a quarter box of row must still lie upstream of the landing point
    if back_x0 + travel > landing_x - 0.25 * L:
        raise SetupError(
            f"configuration: '{_SECTION}.n_boxes' = {n_boxes} is too short a row: the stream must "
            f"still land on it at the end (about {analysed + 0.25 + after:g} boxes are needed "
            f"for analysed_box = {analysed} and run_after_fill = {after:g})"
        )
    margin = 2.0 * d_max
    box_lo = (min(back_x0, 0.0) - margin, -margin, -margin)
    box_hi = (
        max(box_front_x0 + travel, x_top) + margin,
        W + margin,
        max(z_top + chute_wall, feed_z1, rim_top) + margin,
    )

    particles_per_box = rho_b * L * W * H / particle_mass
    expected = particle_rate * total * dt
    radii = tuple(float(r) for r in dist.radii)
    fractions = tuple(float(w) for w in dist.mass_fractions)
    setup = ChuteCoolerSetup(
        radii=radii,
        mass_fractions=fractions,
        r_min=r_min,
        r_max=r_max,
        particle_mass=particle_mass,
        n_boxes=n_boxes,
        box_length=L,
        box_width=W,
        box_height=H,
        rim_height=rim_top,
        lead_wall_height=lead_wall,
        analysed_box=analysed,
        hole_size=hole,
        hole_pitch=pitch,
        holes_per_box=(n_hx, n_hy),
        open_area_fraction=open_fraction,
        box_speed=v_box,
        box_front_x0=box_front_x0,
        chute_angle=angle,
        chute_edge=(0.0, z_edge),
        chute_top=(x_top, z_top),
        chute_y=chute_y,
        chute_wall_height=chute_wall,
        mass_rate=mass_rate,
        particle_rate=particle_rate,
        feed_lo=(feed_x0, chute_y[0] + gap, feed_z0),
        feed_hi=(feed_x1, chute_y[1] - gap, feed_z1),
        feed_velocity=feed_velocity,
        insert_every=insert_every,
        exit_speed=exit_speed,
        landing_x=landing_x,
        arrival_time=arrival_time,
        travel=travel,
        timestep=dt,
        skin=skin_factor * r_min,
        startup_steps=startup_steps,
        travel_steps=travel_steps,
        total_steps=total,
        dump_every=dump_every,
        vtk_every=vtk_every,
        print_every=dump_every,
        thermo_every=max(1, total // 50),
        box_lo=box_lo,
        box_hi=box_hi,
        particles_per_box=particles_per_box,
        expected_particles=expected,
        seeds=insertion_seeds(seed, dist.n_classes),
    )
    counts = {
        "chute": len(chute_triangles(setup)),
        "boxes": len(box_row_triangles(setup)),
    }
    object.__setattr__(setup, "n_triangles", counts)
    return setup
