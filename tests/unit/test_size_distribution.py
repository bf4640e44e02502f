"""Tests of demcal.particles.size_distribution: sieve classes, number fractions, statistics,
scaling."""

from __future__ import annotations

import math

import numpy as np
import pytest

from demcal.particles.size_distribution import (
    SINTER_FINES_SIEVE_MM,
    SizeDistribution,
    from_sieve_analysis,
    monodisperse,
    sinter_fines,
)

MM = 1e-3


def test_two_classes_by_hand() -> None:
    # equal masses of radius 1 mm and 2 mm spheres: 8 small per large one
    dist = SizeDistribution(np.array([1.0, 2.0]) * MM, np.array([0.5, 0.5]))
    np.testing.assert_allclose(dist.number_fractions, [8 / 9, 1 / 9])
    assert dist.mean_radius == pytest.approx((8 * 1 + 2) / 9 * MM)
    mean = 10 / 9
    sd = math.sqrt((8 * (1 - mean) ** 2 + (2 - mean) ** 2) / 9) * MM
    assert dist.sd_radius == pytest.approx(sd)
    assert dist.mass_mean_radius == pytest.approx(1.5 * MM)
    assert dist.mass_sd_radius == pytest.approx(0.5 * MM)
    v1 = 4 / 3 * math.pi * MM**3
    assert dist.mean_particle_volume == pytest.approx((8 * v1 + 8 * v1) / 9)
    # 9 particles (8 small + 1 large) fill 16 v1 of solid
    assert dist.particles_for_volume(16 * v1) == pytest.approx(9.0)
    assert dist.max_radius == 2 * MM and dist.min_radius == 1 * MM


def test_sinter_fines_classes() -> None:
    dist = sinter_fines()
    np.testing.assert_allclose(dist.radii, np.array([1.0, 0.8, 0.625, 0.5, 0.4, 0.315]) * MM)
    np.testing.assert_allclose(dist.mass_fractions, [w for _, w in SINTER_FINES_SIEVE_MM])
    assert dist.mass_fractions.sum() == pytest.approx(1.0, abs=1e-15)
    assert dist.max_radius == pytest.approx(1.0 * MM)
    assert dist.min_radius == pytest.approx(0.315 * MM)


def test_sinter_fines_statistics_against_brute_force_population() -> None:
    dist = sinter_fines()
    # build an explicit particle population with the number fractions and check that it
    # carries the sieve's mass fractions, then take plain sample statistics of it
    counts = np.round(dist.number_fractions * 1_000_000).astype(int)
    radii = np.repeat(dist.radii, counts)
    masses = np.array([c * r**3 for c, r in zip(counts, dist.radii, strict=True)])
    np.testing.assert_allclose(masses / masses.sum(), dist.mass_fractions, rtol=1e-4)
    assert radii.mean() == pytest.approx(dist.mean_radius, rel=1e-5)
    assert radii.std() == pytest.approx(dist.sd_radius, rel=1e-4)
    assert dist.mean_particle_volume == pytest.approx(
        float(np.mean(4 / 3 * np.pi * radii**3)), rel=1e-4
    )


def test_sinter_fines_against_paper_table1() -> None:
    """The documented comparison with Table 1 (mean 0.732 mm, sd 0.410 mm)."""
    dist = sinter_fines()
    assert dist.mean_radius / MM == pytest.approx(0.533, abs=5e-4)
    assert dist.sd_radius / MM == pytest.approx(0.202, abs=5e-4)
    assert dist.mass_mean_radius / MM == pytest.approx(0.778, abs=5e-4)
    assert dist.mass_sd_radius / MM == pytest.approx(0.230, abs=5e-4)
    # mass-weighted mean within 7 % of the paper; no weighting reaches the paper's sd
    assert abs(dist.mass_mean_radius / (0.732 * MM) - 1) < 0.07
    spread_bound = (dist.max_radius - dist.min_radius) / 2
    assert spread_bound < 0.410 * MM


def test_scale_factor_coarse_grains_radii_only() -> None:
    base = sinter_fines()
    coarse = sinter_fines(scale=2.5)
    np.testing.assert_allclose(coarse.radii, 2.5 * base.radii)
    np.testing.assert_allclose(coarse.mass_fractions, base.mass_fractions)
    np.testing.assert_allclose(coarse.number_fractions, base.number_fractions)
    assert coarse.mean_radius == pytest.approx(2.5 * base.mean_radius)
    assert coarse.sd_radius == pytest.approx(2.5 * base.sd_radius)
    # the same solid volume needs 2.5^3 times fewer particles
    volume = 1e-4
    assert coarse.particles_for_volume(volume) == pytest.approx(
        base.particles_for_volume(volume) / 2.5**3
    )


def test_truncation_keeps_largest_classes_renormalised() -> None:
    dist = sinter_fines(n_largest=2)
    np.testing.assert_allclose(dist.radii, [1.0 * MM, 0.8 * MM])
    total = 0.4539 + 0.1571
    np.testing.assert_allclose(dist.mass_fractions, [0.4539 / total, 0.1571 / total])
    both = sinter_fines(scale=3.0, n_largest=4)
    np.testing.assert_allclose(both.radii, 3.0 * np.array([1.0, 0.8, 0.625, 0.5]) * MM)
    assert sinter_fines(n_largest=6).n_classes == 6
    # truncation by size, not by position
    unordered = SizeDistribution(np.array([1.0, 3.0, 2.0]) * MM, np.array([0.2, 0.3, 0.5]))
    np.testing.assert_allclose(unordered.truncated(2).radii, [3.0 * MM, 2.0 * MM])
    np.testing.assert_allclose(unordered.truncated(2).mass_fractions, [0.375, 0.625])
    with pytest.raises(ValueError, match="cannot keep 7"):
        sinter_fines(n_largest=7)
    with pytest.raises(ValueError, match=">= 1"):
        sinter_fines(n_largest=0)


def test_fractional_truncation_keeps_part_of_the_next_class() -> None:
    # 2.5 classes: the two largest whole and half the mass retained on the 1.25 mm sieve.
    dist = sinter_fines(n_largest=2.5)
    np.testing.assert_allclose(dist.radii, [1.0 * MM, 0.8 * MM, 0.625 * MM])
    kept = np.array([0.4539, 0.1571, 0.5 * 0.1033])
    np.testing.assert_allclose(dist.mass_fractions, kept / kept.sum())
    # The share of fines grows continuously between whole numbers: smaller mean particle.
    volumes = [sinter_fines(n_largest=k).mean_particle_volume for k in (3.0, 3.25, 3.5, 3.75, 4.0)]
    assert np.all(np.diff(volumes) < 0)
    assert sinter_fines(n_largest=3.0).n_classes == 3
    for bad in (float("nan"), 6.5, True):
        with pytest.raises(ValueError, match="classes"):
            sinter_fines(n_largest=bad)


def test_monodisperse() -> None:
    dist = monodisperse(0.732 * MM)
    assert dist.mean_radius == pytest.approx(0.732 * MM)
    assert dist.sd_radius == 0.0
    assert dist.number_fractions.tolist() == [1.0]
    v = 4 / 3 * math.pi * (0.732 * MM) ** 3
    assert dist.particles_for_volume(1000 * v) == pytest.approx(1000.0)


def test_from_sieve_analysis_units() -> None:
    dist = from_sieve_analysis([(4.0, 0.25), (2.0, 0.75)])
    np.testing.assert_allclose(dist.radii, [2.0 * MM, 1.0 * MM])
    dist_um = from_sieve_analysis([(400.0, 1.0)], unit=1e-6)
    assert dist_um.radii[0] == pytest.approx(200e-6)


def test_arrays_are_read_only() -> None:
    dist = sinter_fines()
    with pytest.raises(ValueError):
        dist.radii[0] = 1.0


@pytest.mark.parametrize(
    ("radii", "fractions", "fragment"),
    [
        ([], [], "at least one"),
        ([1e-3, 2e-3], [1.0], "2 radii but 1"),
        ([1e-3, -2e-3], [0.5, 0.5], "positive"),
        ([1e-3, 1e-3], [0.5, 0.5], "distinct"),
        ([1e-3, 2e-3], [0.7, 0.2], "sum to 0.9"),
        ([1e-3, 2e-3], [1.2, -0.2], ">= 0"),
    ],
)
def test_invalid_distributions(radii: list, fractions: list, fragment: str) -> None:
    with pytest.raises(ValueError, match=fragment):
        SizeDistribution(np.array(radii), np.array(fractions))


def test_invalid_volume_and_scale() -> None:
    with pytest.raises(ValueError, match="solid_volume"):
        sinter_fines().particles_for_volume(-1.0)
    with pytest.raises(ValueError, match="scale"):
        sinter_fines(scale=0.0)
