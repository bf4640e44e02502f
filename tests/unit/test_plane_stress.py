"""Stresses across the shear plane from a contact list (synthetic contacts, known sums)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from demcal.virtual_tests.shear_cell.plane_stress import (
    CONTACT_COLUMNS,
    band_profile,
    plane_stress,
    plateau_comparison,
    ring_band_forces,
    ring_plane_stress,
)
from demcal.virtual_tests.shear_cell.readout import overlap_area

R, Z = 0.02, 0.015


def contacts(rows: list[tuple[float, ...]]) -> pd.DataFrame:
    return pd.DataFrame(rows, columns=list(CONTACT_COLUMNS))


def test_only_contacts_across_the_plane_inside_the_overlap_count() -> None:
    d = 0.002
    table = contacts(
        [
            # across the plane, particle 1 above: force on the upper one counts as it is
            (0.0, 0.0, Z + d / 2, 0.0, 0.0, Z - d / 2, 1, 2, 0, -0.3, 0.0, 1.0),
            # across the plane, particle 1 below: the force on the upper one is -f
            (0.005, 0.0, Z - d / 2, 0.005, 0.0, Z + d / 2, 3, 4, 0, 0.1, 0.0, -1.0),
            # both above the plane: not counted
            (0.0, 0.005, Z + d, 0.0, 0.005, Z + 2 * d, 5, 6, 0, 5.0, 0.0, 5.0),
            # across the plane but outside the lower circle, which moved 8 mm in -x
            (0.015, 0.0, Z + d / 2, 0.015, 0.0, Z - d / 2, 7, 8, 0, -9.0, 0.0, 9.0),
        ]
    )
    got = plane_stress(table, Z, R, travel=-0.008, margin=0.0)
    area = overlap_area(R, 0.008)
    assert got["n"] == 2
    assert got["area"] == pytest.approx(area)
    assert got["tau"] == pytest.approx(0.4 / area)
    assert got["sigma"] == pytest.approx(2.0 / area)
    assert got["mu"] == pytest.approx(0.2)
    # A margin of 7.5 mm from both walls leaves only the central contact.
    central = plane_stress(table, Z, R, travel=-0.008, margin=0.0075)
    assert central["n"] == 1 and central["mu"] == pytest.approx(0.3)


def test_an_empty_plane_and_a_bad_margin() -> None:
    table = contacts([(0.0, 0.0, Z + 0.002, 0.0, 0.0, Z + 0.004, 1, 2, 0, 1.0, 0.0, 1.0)])
    got = plane_stress(table, Z, R, travel=0.0, margin=0.0)
    assert got["n"] == 0 and np.isnan(got["mu"])
    with pytest.raises(ValueError, match="margin"):
        plane_stress(table, Z, R, travel=0.0, margin=R)


R_I = 0.01


def test_ring_torque_of_the_contacts_across_the_annulus() -> None:
    d = 0.002
    table = contacts(
        [
            # at r = 15 mm on +x, particle 1 above: 0.5 N along +y is a torque of +7.5e-3 N m
            (0.015, 0.0, Z + d / 2, 0.015, 0.0, Z - d / 2, 1, 2, 0, 0.2, 0.5, 2.0),
            # at r = 12 mm on +y, particle 1 below: the force on the upper one is (-0.3, 0, 1)
            (0.0, 0.012, Z - d / 2, 0.0, 0.012, Z + d / 2, 3, 4, 0, 0.3, 0.0, -1.0),
            # a tilted branch line: it pierces the plane at r = 14 mm on -x (force along -y)
            (-0.013, 0.0, Z + d / 2, -0.015, 0.0, Z - d / 2, 5, 6, 0, 0.0, -0.4, 1.0),
            # across the plane but in the core (r = 8 mm): not counted
            (0.008, 0.0, Z + d / 2, 0.008, 0.0, Z - d / 2, 7, 8, 0, 0.0, 9.0, 9.0),
            # both below the plane: not counted
            (0.0, -0.015, Z - d, 0.0, -0.015, Z - 2 * d, 9, 10, 0, 9.0, 0.0, 9.0),
        ]
    )
    got = ring_plane_stress(table, Z, R_I, R, margin=0.0)
    torque = 0.015 * 0.5 - 0.012 * (-0.3) + (-0.014) * (-0.4)
    assert got["n"] == 3
    assert got["torque"] == pytest.approx(torque)
    assert got["area"] == pytest.approx(np.pi * (R**2 - R_I**2))
    # The wall readout's uniform-stress relation between torque and shear stress.
    assert got["tau"] == pytest.approx(3.0 * torque / (2.0 * np.pi * (R**3 - R_I**3)))
    assert got["sigma"] == pytest.approx(4.0 / got["area"])
    assert got["mu"] == pytest.approx(got["tau"] / got["sigma"])
    # 2.5 mm from both walls: only the crossings at 14 and 15 mm remain.
    kept = ring_plane_stress(table, Z, R_I, R, margin=0.0025)
    assert kept["n"] == 2
    assert kept["torque"] == pytest.approx(0.015 * 0.5 + 0.014 * 0.4)
    r_in, r_out = R_I + 0.0025, R - 0.0025
    assert kept["sigma"] == pytest.approx(3.0 / (np.pi * (r_out**2 - r_in**2)))


def test_a_uniform_azimuthal_stress_reads_back() -> None:
    # Contacts on a fine polar grid, each carrying tau0 * (its cell's area) azimuthally and
    # sigma0 * area vertically: the readout returns tau0 and sigma0 (the torque relation holds
    # for a stress uniform over the annulus).
    tau0, sigma0 = 300.0, 1000.0
    radii = np.linspace(R_I, R, 201)
    r = 0.5 * (radii[1:] + radii[:-1])
    theta = np.linspace(0.0, 2.0 * np.pi, 120, endpoint=False)
    rr, tt = np.meshgrid(r, theta)
    cell = (np.pi * (radii[1:] ** 2 - radii[:-1] ** 2) / len(theta))[None, :] * np.ones_like(rr)
    x, y = (rr * np.cos(tt)).ravel(), (rr * np.sin(tt)).ravel()
    ft = tau0 * cell.ravel()
    n = x.size
    table = pd.DataFrame(
        {
            "x1": x,
            "y1": y,
            "z1": np.full(n, Z + 0.001),
            "x2": x,
            "y2": y,
            "z2": np.full(n, Z - 0.001),
            "id1": np.arange(n),
            "id2": np.arange(n) + n,
            "periodic": np.zeros(n),
            "fx": -ft * np.sin(tt.ravel()),
            "fy": ft * np.cos(tt.ravel()),
            "fz": sigma0 * cell.ravel(),
        }
    )
    got = ring_plane_stress(table, Z, R_I, R, margin=0.0)
    assert got["tau"] == pytest.approx(tau0, rel=1e-4)
    assert got["sigma"] == pytest.approx(sigma0, rel=1e-9)
    assert got["mu"] == pytest.approx(0.3, rel=1e-4)


def test_ring_margin_must_leave_an_annulus() -> None:
    table = contacts([(0.015, 0.0, Z + 0.002, 0.015, 0.0, Z + 0.004, 1, 2, 0, 1.0, 0.0, 1.0)])
    assert ring_plane_stress(table, Z, R_I, R, margin=0.0)["n"] == 0
    with pytest.raises(ValueError, match="margin"):
        ring_plane_stress(table, Z, R_I, R, margin=0.005)
    with pytest.raises(ValueError, match="margin"):
        ring_plane_stress(table, Z, R_I, R, margin=-0.001)


def test_plateau_comparison_averages_the_snapshots_inside_each_window() -> None:
    plane = pd.DataFrame(
        {
            "cycle": [0, 0, 0, 0, 0, 1, 1],
            "phase": [1, 1, 1, 3, 3, 1, 3],
            "time": [0.1, 0.2, 0.3, 0.5, 0.6, 1.1, 1.5],
            "mu": [0.9, 0.40, 0.44, 0.50, 0.30, 0.45, 0.41],
        }
    )
    values = pd.DataFrame(
        {
            "cycle": [0, 1],
            # The first snapshot (t = 0.1) lies before the pre-shear's steady window.
            "psh_t_start": [0.15, 1.0],
            "psh_t_end": [0.35, 1.2],
            "sh_t_start": [0.45, 1.4],
            "sh_t_end": [0.65, 1.45],
            "mu_psh_cycle": [0.43, 0.46],
            "mu_psh": [0.445, 0.445],
            "mu_sh": [0.41, 0.40],
        }
    )
    got = plateau_comparison(plane, values).set_index(["cycle", "phase"])
    assert got.loc[(0, "psh"), "snapshots"] == 2
    assert got.loc[(0, "psh"), "mu_plane"] == pytest.approx(0.42)
    assert got.loc[(0, "psh"), "mu_wall"] == pytest.approx(0.43)  # the cycle's own reading
    assert got.loc[(0, "sh"), "mu_plane_sd"] == pytest.approx(np.std([0.5, 0.3], ddof=1))
    assert got.loc[(1, "psh"), "mu_plane"] == pytest.approx(0.45)
    # No snapshot in cycle 1's shear window: NaN, not a reading from outside it.
    assert got.loc[(1, "sh"), "snapshots"] == 0 and np.isnan(got.loc[(1, "sh"), "mu_plane"])


def test_band_forces_split_the_annulus_into_equal_widths() -> None:
    d = 0.002
    table = contacts(
        [
            # inner band (10-13.3 mm): r = 11 mm on +x, azimuthal force +0.2 N
            (0.011, 0.0, Z + d / 2, 0.011, 0.0, Z - d / 2, 1, 2, 0, 0.0, 0.2, 1.0),
            # outer band (16.7-20 mm): r = 18 mm on +y, particle 1 below: force on the upper
            # one is (+0.3, 0, 2); along the azimuth at +y that is -0.3 N
            (0.0, 0.018, Z - d / 2, 0.0, 0.018, Z + d / 2, 3, 4, 0, -0.3, 0.0, -2.0),
            # outer wall exactly: the last band
            (-0.02, 0.0, Z + d / 2, -0.02, 0.0, Z - d / 2, 5, 6, 0, 0.0, -0.1, 0.5),
            # not across the plane
            (0.015, 0.0, Z + d, 0.015, 0.0, Z + 2 * d, 7, 8, 0, 0.0, 9.0, 9.0),
        ]
    )
    got = ring_band_forces(table, Z, R_I, R, bands=3)
    assert got["azimuthal_force_0"] == pytest.approx(0.2)
    assert got["normal_force_0"] == pytest.approx(1.0)
    assert got["azimuthal_force_1"] == 0.0 and got["normal_force_1"] == 0.0
    # At -x a force along -y points along the azimuth (+0.1 N).
    assert got["azimuthal_force_2"] == pytest.approx(-0.3 + 0.1)
    assert got["normal_force_2"] == pytest.approx(2.5)
    with pytest.raises(ValueError, match="bands"):
        ring_band_forces(table, Z, R_I, R, bands=0)


def test_band_profile_sums_each_window_band_by_band() -> None:
    bands = 2
    edges = np.linspace(R_I, R, bands + 1)
    area = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    # Two snapshots in the pre-shear window, one outside it; normal force per band set so that
    # the inner band carries 800 Pa and the outer 1200 Pa on average.
    plane = pd.DataFrame(
        {
            "cycle": [0, 0, 0],
            "phase": [1, 1, 1],
            "time": [0.2, 0.3, 0.05],
            "normal_force_0": [700.0 * area[0], 900.0 * area[0], 1.0],
            "normal_force_1": [1200.0 * area[1], 1200.0 * area[1], 1.0],
            "azimuthal_force_0": [-0.3 * 700 * area[0], -0.3 * 900 * area[0], 5.0],
            "azimuthal_force_1": [-0.5 * 1200 * area[1], -0.5 * 1200 * area[1], 5.0],
        }
    )
    values = pd.DataFrame(
        {
            "cycle": [0],
            "psh_t_start": [0.1],
            "psh_t_end": [0.4],
            "sh_t_start": [np.nan],
            "sh_t_end": [np.nan],
            "mu_psh_cycle": [0.45],
            "mu_sh": [np.nan],
        }
    )
    got = band_profile(plane, values, R_I, R, bands).set_index("band")
    assert list(got["phase"]) == ["psh", "psh"]  # the shear has no window
    assert got.loc[0, "sigma"] == pytest.approx(800.0)
    assert got.loc[1, "sigma"] == pytest.approx(1200.0)
    mean = (800.0 * area[0] + 1200.0 * area[1]) / area.sum()
    assert got.loc[1, "sigma_rel"] == pytest.approx(1200.0 / mean)
    assert got.loc[0, "mu"] == pytest.approx(0.3) and got.loc[1, "mu"] == pytest.approx(0.5)
    annulus = (0.3 * 800.0 * area[0] + 0.5 * 1200.0 * area[1]) / (mean * area.sum())
    assert got.loc[0, "mu_annulus"] == pytest.approx(annulus)
    assert got.loc[0, "r_hi"] == pytest.approx(edges[1]) and got.loc[1, "mu_wall"] == 0.45
