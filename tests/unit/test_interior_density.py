"""The ring interior's solid fraction from a snapshot: centre count against volume inside."""

from __future__ import annotations

import math

import numpy as np
import pytest

from demcal.virtual_tests.shear_cell.interior_density import (
    interior_fractions,
    sphere_fraction_inside,
)


def test_sphere_fraction_inside_is_a_cap() -> None:
    r = np.array([1.0, 1.0, 1.0, 1.0, 2.0])
    depth = np.array([-1.5, 0.0, 1.0, 3.0, -1.0])
    frac = sphere_fraction_inside(depth, r)
    # Cap of height 1 of a sphere of radius 2: pi h^2 (3R - h) / 3 over 4/3 pi R^3.
    assert frac == pytest.approx([0.0, 0.5, 1.0, 1.0, (1.0 * 5.0 / 3.0) / (4.0 / 3.0 * 8.0)])


def test_one_sphere_on_the_top_plane_counts_half_by_volume() -> None:
    # Centre on the top of the annulus, well inside radially: half its volume is inside, and
    # by centre it counts not at all (the plane is not inside, '<').
    points = np.array([[0.5, 0.0, 1.0]])
    out = interior_fractions(points, np.array([0.05]), 0.3, 0.7, 0.0, 1.0)
    annulus = math.pi * (0.7**2 - 0.3**2)
    assert out.by_volume == pytest.approx(0.5 * 4.0 / 3.0 * math.pi * 0.05**3 / annulus)
    assert (out.by_centre, out.n_centres) == (0.0, 0)


def test_a_uniform_gas_of_spheres_gives_the_same_fraction_both_ways() -> None:
    # Centres uniform in a larger box: no layering, so both estimates agree within the scatter
    # of the boundary particles (about 1 % with 20 000 centres in the annulus).
    rng = np.random.default_rng(5)
    n = 200_000
    points = rng.uniform([-1.0, -1.0, -0.2], [1.0, 1.0, 1.2], size=(n, 3))
    radii = rng.uniform(0.01, 0.02, size=n)
    out = interior_fractions(points, radii, 0.3, 0.7, 0.0, 1.0)
    expected = float(np.sum(4.0 / 3.0 * math.pi * radii**3)) / (2.0 * 2.0 * 1.4)
    assert out.by_volume == pytest.approx(expected, rel=0.02)
    assert out.by_centre == pytest.approx(out.by_volume, rel=0.02)


def test_layers_cut_by_the_boundary_bias_the_centre_count() -> None:
    # Spheres of radius 0.1 in flat layers at z = 0.1, 0.3, ...: a region from 0 to 0.5 holds
    # three layers by centre, but only two and a half by volume.
    xy = np.stack(np.meshgrid(np.arange(-0.9, 1.0, 0.2), np.arange(-0.9, 1.0, 0.2)), -1)
    layers = [
        np.column_stack([xy.reshape(-1, 2), np.full(xy.size // 2, z)]) for z in (0.1, 0.3, 0.5, 0.7)
    ]
    points = np.concatenate(layers)
    out = interior_fractions(points, np.full(len(points), 0.1), 0.0, 5.0, 0.0, 0.5)
    # The third layer's centres sit on the top plane (not counted), the fourth's reach
    # down to it; radially every sphere is inside.
    assert out.by_centre / out.by_volume == pytest.approx(2.0 / 2.5, rel=1e-9)


def test_bad_input_is_rejected() -> None:
    with pytest.raises(ValueError, match="empty annulus"):
        interior_fractions(np.zeros((1, 3)), np.ones(1), 0.5, 0.4, 0.0, 1.0)
    with pytest.raises(ValueError, match="points must be"):
        interior_fractions(np.zeros((2, 2)), np.ones(2), 0.1, 0.4, 0.0, 1.0)
