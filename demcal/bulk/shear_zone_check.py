"""The shear zone of a finished ring shear-cell deck, from its particle snapshot.

Every shear-cell deck writes the particles' positions and velocities at the end of its first
pre-shear (``files.snapshot`` of its ``case.json``). For a ring deck :func:`shear_zone_check`
turns that snapshot into the azimuthal velocity profile across the bed
(:mod:`demcal.virtual_tests.shear_cell.velocity_profile`) over the annulus where the deck
reads its interior density, and into the inertial numbers that go with it: of the zone where
the profile is steepest, of the interior region (where rho_b is read), of the whole bed sheared
evenly, and the nominal one of a band ten diameters wide that the deck's set-up records.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import NamedTuple

import pandas as pd

from demcal.bulk.values import MissingOutputError, read_case_record
from demcal.engine_io.vtk_file import read_vtk_particles
from demcal.virtual_tests.shear_cell.setup import inertial_number
from demcal.virtual_tests.shear_cell.velocity_profile import (
    azimuthal_profile,
    mean_gradient,
    shear_zone,
)

__all__ = ["ShearZoneCheck", "shear_zone_check"]


class ShearZoneCheck(NamedTuple):
    """The shear zone of one deck (see :func:`shear_zone_check`)."""

    #: :func:`~demcal.virtual_tests.shear_cell.velocity_profile.azimuthal_profile`'s slices
    #: with ``z_d``, the slice centre over the mean particle diameter.
    profile: pd.DataFrame
    #: ``speed`` (floor at the mean radius, m/s), ``pressure`` (Pa), ``diameter`` (mean particle
    #: diameter d, m), ``bed_d`` (bed height / d), ``zone_lo_d`` and ``zone_hi_d`` (where the
    #: speed falls below 0.9 and 0.1 of the floor's, / d), ``width_d``, and the inertial numbers
    #: ``I_peak`` (steepest slice pair), ``I_interior`` (the interior region's mean gradient),
    #: ``I_bed`` (the whole bed sheared evenly) and ``I_nominal`` (a band ten diameters wide).
    summary: dict[str, float]


def shear_zone_check(case_dir: str | Path, slice_diameters: float = 0.5) -> ShearZoneCheck:
    """Velocity profile and shear zone of a finished ring deck at the end of its first pre-shear.

    Parameters
    ----------
    case_dir : str or Path
        A finished ring shear-cell case directory.
    slice_diameters : float
        Slice height in mean particle diameters.

    Returns
    -------
    ShearZoneCheck

    Raises
    ------
    demcal.bulk.values.MissingOutputError
        Not a ring deck, or no snapshot (the run did not reach the end of its first pre-shear).
    ValueError
        A profile without a shear zone (see
        :func:`~demcal.virtual_tests.shear_cell.velocity_profile.shear_zone`).
    """
    case_dir = Path(case_dir)
    record = read_case_record(case_dir)
    setup = record.get("setup", {})
    if record.get("test") != "shear_cell" or setup.get("geometry") != "ring":
        raise MissingOutputError(f"{case_dir}: not a ring shear-cell deck")
    snapshot = case_dir / record["files"]["snapshot"]
    if not snapshot.is_file():
        raise MissingOutputError(f"{snapshot}: snapshot missing (did the run fail?)")
    moving = [s for s in setup["segments"] if s["moving"] and s["snapshot"]]
    if not moving:
        raise MissingOutputError(f"{case_dir}: no sheared segment ends in the snapshot")
    speed = float(moving[0]["velocity"])
    mean_radius = float(setup["mean_radius"])
    diameter = 2.0 * float(setup["reference_radius"])
    z_floor = float(record["readout"]["z_floor"])
    particles = read_vtk_particles(snapshot, arrays=["v"])
    # The annulus where the deck reads rho_b (bulk_density: interior), else the whole ring
    # and a band two diameters high about the plane.
    if setup.get("bulk_density") == "interior":
        r_lo, r_hi = float(setup["interior_r_lo"]), float(setup["interior_r_hi"])
        z_lo, z_hi = float(setup["interior_z_lo"]), float(setup["interior_z_hi"])
    else:
        r_lo, r_hi = float(setup["inner_radius"]), float(setup["radius"])
        z_shear = float(record["readout"]["z_shear"])
        z_lo, z_hi = z_shear - diameter, z_shear + diameter
    profile = azimuthal_profile(
        particles.points,
        particles.arrays["v"],
        speed / mean_radius,
        r_lo,
        r_hi,
        slice_diameters * diameter,
        z_floor,
    )
    profile["z_d"] = (profile["z"] - z_floor) / diameter
    zone = shear_zone(profile)
    pressure = float(setup["normal_stress"])
    density = float(record["material"]["density"])
    # I = gamma_dot d / sqrt(p / rho_p) with gamma_dot = |v| |du/dz| at the mean radius.
    scale = abs(speed) * diameter / math.sqrt(pressure / density)
    bed = float(setup["fill_height"])
    summary = {
        "speed": abs(speed),
        "pressure": pressure,
        "diameter": diameter,
        "bed_d": bed / diameter,
        "zone_lo_d": (zone.z_floor_side - z_floor) / diameter,
        "zone_hi_d": (zone.z_lid_side - z_floor) / diameter,
        "width_d": zone.width / diameter,
        "I_peak": scale * zone.peak_gradient,
        "I_interior": scale * mean_gradient(profile, z_lo, z_hi),
        "I_bed": scale / bed,
        "I_nominal": inertial_number(abs(speed), 10.0, pressure, density),
    }
    return ShearZoneCheck(profile, summary)
