"""Angle of repose on synthetic heaps: random sphere packings filling cones of known angle."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from scipy.spatial import cKDTree

from demcal.virtual_tests.angle_of_repose.readout import (
    LAYER_DIAMETERS,
    NotAHeapError,
    angle_of_repose,
)

R_MIN, R_MAX = 0.35e-3, 0.8e-3  # particle radii, m (sinter-fines range)
HEIGHTS = {25.0: 0.016, 35.0: 0.020, 45.0: 0.024}  # heap height per angle, m


def pack_heap(
    slope_deg: Callable[[np.ndarray], np.ndarray],
    height: float,
    centre: tuple[float, float],
    base_z: float,
    seed: int,
    rounds: int = 30,
    batch: int = 20000,
) -> tuple[np.ndarray, np.ndarray]:
    """Random non-overlapping spheres filling a heap with apex above ``centre``.

    The free surface at azimuth phi has slope ``slope_deg(phi)``; every sphere lies inside it
    and above the plate. Candidates drawn uniformly are accepted when they overlap neither the
    spheres already placed nor an earlier candidate of the same round.

    Returns positions (n, 3) in m and radii (n,) in m.
    """
    rng = np.random.default_rng(seed)
    reach = height / np.tan(np.radians(slope_deg(np.linspace(0.0, 2 * np.pi, 721)).min()))
    pos = np.empty((0, 3))
    rad = np.empty(0)
    for _ in range(rounds):
        r = rng.uniform(R_MIN, R_MAX, batch)
        rho = reach * np.sqrt(rng.random(batch))
        phi = rng.uniform(0.0, 2 * np.pi, batch)
        z = rng.uniform(0.0, height, batch)
        alpha = np.radians(slope_deg(phi))
        # Distance from the centre to the surface line is ((H - z)/tan a - rho) sin a >= r.
        inside = (rho <= (height - z) / np.tan(alpha) - r / np.sin(alpha)) & (z >= r)
        cand = np.column_stack(
            [centre[0] + rho * np.cos(phi), centre[1] + rho * np.sin(phi), base_z + z]
        )[inside]
        r = r[inside]
        if rad.size:
            near = cKDTree(cand).sparse_distance_matrix(
                cKDTree(pos), 2 * R_MAX, output_type="ndarray"
            )
            hit = near["v"] < r[near["i"]] + rad[near["j"]]
            free = np.ones(r.size, dtype=bool)
            free[near["i"][hit]] = False
            cand, r = cand[free], r[free]
        pairs = cKDTree(cand).query_pairs(2 * R_MAX, output_type="ndarray")
        gap = np.linalg.norm(cand[pairs[:, 0]] - cand[pairs[:, 1]], axis=1)
        pairs = pairs[gap < r[pairs[:, 0]] + r[pairs[:, 1]]]
        keep = np.ones(r.size, dtype=bool)
        for i, j in pairs:
            if keep[i] and keep[j]:
                keep[j] = False
        pos = np.vstack([pos, cand[keep]])
        rad = np.concatenate([rad, r[keep]])
    return pos, rad


def _cone(angle: float) -> Callable[[np.ndarray], np.ndarray]:
    return lambda phi: np.full(np.shape(phi), angle)


def _assert_no_overlap(pos: np.ndarray, rad: np.ndarray) -> None:
    pairs = cKDTree(pos).query_pairs(2 * R_MAX, output_type="ndarray")
    gap = np.linalg.norm(pos[pairs[:, 0]] - pos[pairs[:, 1]], axis=1)
    assert np.all(gap >= rad[pairs[:, 0]] + rad[pairs[:, 1]])


@pytest.mark.parametrize("angle", [25.0, 35.0, 45.0])
def test_cone_angle_recovered_within_one_degree(angle: float) -> None:
    height = HEIGHTS[angle]
    pos, rad = pack_heap(_cone(angle), height, (0.0, 0.0), 0.0, seed=int(angle))
    _assert_no_overlap(pos, rad)
    assert 5000 < rad.size < 15000
    res = angle_of_repose(pos, rad, (0.0, 0.0), 0.0)
    assert res.angle_deg == pytest.approx(angle, abs=1.0)
    # The variants use the same slices; the slice-to-slice mean is the noisier one.
    assert res.angle_mean_slices_deg == pytest.approx(angle, abs=1.5)
    assert res.angle_fit_deg == pytest.approx(angle, abs=1.5)
    # Sectors of a symmetric cone scatter about the same angle.
    assert np.all(np.abs(res.sector_angles_deg - angle) < 2.5)
    assert res.sector_spread_deg < 1.5
    # Heap top lies within one particle diameter of the apex; radii shrink upwards.
    assert height - 2 * R_MAX < res.heap_height <= height
    assert res.z_high - res.z_low == pytest.approx(0.5 * res.heap_height)
    mid = (res.slice_z > res.z_low) & (res.slice_z < res.z_high)
    assert np.all(np.diff(res.slice_radii[mid]) < 0.0)
    assert res.slice_counts.sum() == rad.size == res.n_particles


def test_off_centre_cone_on_raised_plate() -> None:
    centre, base_z, angle = (0.031, -0.012), 0.005, 35.0
    pos, rad = pack_heap(_cone(angle), HEIGHTS[angle], centre, base_z, seed=7)
    res = angle_of_repose(pos, rad, centre, base_z)
    assert res.angle_deg == pytest.approx(angle, abs=1.0)
    assert np.all(np.abs(res.sector_angles_deg - angle) < 2.5)
    assert res.heap_height == pytest.approx(HEIGHTS[angle], abs=2 * R_MAX)
    # The hull method ignores the centre; the sectors need it. About an axis 5 mm off, the
    # sectors facing away from it see a wider envelope.
    shifted = angle_of_repose(pos, rad, (centre[0] + 5e-3, centre[1]), base_z)
    assert shifted.angle_deg == res.angle_deg
    assert shifted.sector_spread_deg > 2 * res.sector_spread_deg
    # About the origin, outside the heap, the sectors facing away see no flank at all; a pile
    # this tall is still read (the hull does not need the centre).
    outside = angle_of_repose(pos, rad, (0.0, 0.0), base_z)
    assert outside.angle_deg == res.angle_deg
    assert not np.all(outside.sector_angles_deg < 90.0)


def test_asymmetric_heap_sector_angles() -> None:
    # Slope 45 deg towards +x, 25 deg towards -x, symmetric about the x axis.
    def slope(phi: np.ndarray) -> np.ndarray:
        return 35.0 + 10.0 * np.cos(phi)

    pos, rad = pack_heap(slope, 0.018, (0.0, 0.0), 0.0, seed=11)
    res = angle_of_repose(pos, rad, (0.0, 0.0), 0.0, n_sectors=8)
    np.testing.assert_allclose(res.sector_centres_deg, np.arange(8) * 45.0)
    # A sector's envelope angle lies within the range of slopes it spans (2 deg of scatter
    # from the single outermost particle per slice allowed).
    half = np.radians(22.5)
    for k, got in enumerate(res.sector_angles_deg):
        spanned = slope(np.radians(45.0 * k) + np.linspace(-half, half, 91))
        assert spanned.min() - 2.0 < got < spanned.max() + 2.0
    # Steepest towards +x, decreasing on both sides towards -x.
    s = res.sector_angles_deg
    assert s[0] > s[1] > s[2] > s[3]
    assert s[0] > s[7] > s[6] > s[5]
    assert s[0] - s[4] > 15.0
    assert res.sector_spread_deg > 5.0
    assert 25.0 < res.angle_deg < 45.0


def test_contact_filter_drops_loose_particles() -> None:
    angle = 35.0
    height = HEIGHTS[angle]
    pos, rad = pack_heap(_cone(angle), height, (0.0, 0.0), 0.0, seed=3)
    # Loose particles rolling down the upper slope, 3 mm outside the surface, one contact.
    rng = np.random.default_rng(0)
    n_loose = 60
    z = rng.uniform(0.55, 0.75, n_loose) * height
    phi = rng.uniform(0.0, 2 * np.pi, n_loose)
    rho = (height - z) / np.tan(np.radians(angle)) + 3e-3
    loose = np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])
    all_pos = np.vstack([pos, loose])
    all_rad = np.concatenate([rad, np.full(n_loose, 0.6e-3)])
    contacts = np.concatenate([np.full(rad.size, 4), np.ones(n_loose, dtype=int)])

    filtered = angle_of_repose(all_pos, all_rad, (0.0, 0.0), 0.0, contacts=contacts)
    unfiltered = angle_of_repose(all_pos, all_rad, (0.0, 0.0), 0.0)
    assert filtered.n_particles == rad.size
    assert unfiltered.n_particles == rad.size + n_loose
    assert filtered.angle_deg == pytest.approx(angle, abs=1.0)
    # Upper slices widened by the loose particles make the unfiltered heap look steeper.
    assert unfiltered.angle_deg > angle + 2.0


def test_bad_input() -> None:
    pos = np.zeros((100, 3))
    rad = np.full(100, 1e-3)
    with pytest.raises(ValueError, match="positions"):
        angle_of_repose(np.zeros((100, 2)), rad, (0.0, 0.0), 0.0)
    with pytest.raises(ValueError, match="radii"):
        angle_of_repose(pos, rad[:10], (0.0, 0.0), 0.0)
    with pytest.raises(ValueError, match="centre_xy"):
        angle_of_repose(pos, rad, (0.0, 0.0, 0.0), 0.0)
    with pytest.raises(ValueError, match="contacts"):
        angle_of_repose(pos, rad, (0.0, 0.0), 0.0, contacts=np.ones(3))
    with pytest.raises(ValueError, match="n_slices"):
        angle_of_repose(pos, rad, (0.0, 0.0), 0.0, n_slices=2)


def test_too_few_particles_on_the_plate_are_no_heap() -> None:
    # All below the plate; then 100 on it rolling about with one contact each, 30 of them
    # with two: 60 are needed for 20 slices.
    rng = np.random.default_rng(3)
    pos = np.column_stack([rng.uniform(-0.04, 0.04, (100, 2)), np.full(100, 1e-3)])
    rad = np.full(100, 1e-3)
    with pytest.raises(NotAHeapError, match="no heap: 0 of the 0 particles on the plate,"):
        angle_of_repose(pos, rad, (0.0, 0.0), 1.0)
    contacts = np.where(np.arange(100) < 30, 2, 1)
    with pytest.raises(
        NotAHeapError,
        match=r"no heap: 30 of the 100 particles on the plate with 2\+ contacts, fewer than the "
        r"60 that 20 slices need",
    ):
        angle_of_repose(pos, rad, (0.0, 0.0), 0.0, contacts=contacts)


@pytest.mark.parametrize("seed", range(3))
def test_particles_spread_over_the_plate_are_no_heap(seed: int) -> None:
    # A layer on the plate and a sparse second one over the same disc, as spheres without
    # rolling resistance leave them: the hull "angle" reads 55-75 deg, some sectors above 90.
    rng = np.random.default_rng(seed)
    radius = 1.5e-3

    def layer(n: int, z: float) -> np.ndarray:
        rho = 0.04 * np.sqrt(rng.random(n))
        phi = rng.uniform(0.0, 2 * np.pi, n)
        return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), np.full(n, z)])

    pos = np.vstack([layer(500, radius), layer(150, 2.6 * radius)])
    with pytest.raises(NotAHeapError, match=r"no heap: .* 5\.4 mm \(1\.8 mean diameters\) high"):
        angle_of_repose(pos, np.full(len(pos), radius), (0.0, 0.0), 0.0)


def test_a_standing_column_reads_vertical() -> None:
    # A cohesive bulk standing as a column after the lift: not a layer, its flank is vertical.
    rng = np.random.default_rng(5)
    radius, column_radius, height = 1.5e-3, 0.02, 0.06
    n = 4000
    rho = column_radius * np.sqrt(rng.random(n))
    phi = rng.uniform(0.0, 2 * np.pi, n)
    pos = np.column_stack([rho * np.cos(phi), rho * np.sin(phi), rng.uniform(0.0, height, n)])
    res = angle_of_repose(pos, np.full(n, radius), (0.0, 0.0), 0.0)
    assert res.angle_deg == pytest.approx(90.0, abs=3.0)
    assert res.heap_height > 10 * 2 * radius


@pytest.mark.parametrize("seed", range(2))
def test_a_flat_heap_below_the_layer_height_is_read(seed: int) -> None:
    # A low friction bulk: an 8-degree cone about three mean diameters high narrows upwards all
    # round, so it is a heap although it is lower than LAYER_DIAMETERS.
    pos, rad = pack_heap(_cone(8.0), 0.003, (0.0, 0.0), 0.0, seed=seed)
    res = angle_of_repose(pos, rad, (0.0, 0.0), 0.0)
    assert res.heap_height < LAYER_DIAMETERS * 2 * rad.mean()
    assert res.angle_deg == pytest.approx(8.0, abs=1.0)
    assert np.all(np.abs(res.sector_angles_deg - 8.0) < 1.5)
