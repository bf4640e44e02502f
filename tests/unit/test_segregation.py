"""Layer analysis and segregation index on synthetic particle sets with a known layering."""

import math

import numpy as np
import pandas as pd
import pytest

from demcal.application.chute_cooler.box_layers import (
    LAYERS,
    Box,
    assign_classes,
    layer_class_volumes,
    layer_table,
    table_volumes,
)
from demcal.application.chute_cooler.segregation import (
    mean_radii,
    segregation_index,
    sorted_volumes,
)
from demcal.application.chute_cooler.steady_segregation import (
    analyse_segregation,
    segregation_time_series,
    steady_window,
)

RADII = [1.0e-3, 0.8e-3, 0.5e-3]
# equal volume per class: 64 * 1^3 = 125 * 0.8^3 = 512 * 0.5^3 (mm^3 / (4/3 pi))
EQUAL_VOLUME_COUNTS = {1.0e-3: 64, 0.8e-3: 125, 0.5e-3: 512}
BOX = Box(0.0, 0.03, 0.0, 0.02, 0.0, 0.03)


def sphere_volume(r: float) -> float:
    return 4.0 / 3.0 * math.pi * r**3


def layer_points(n: int, layer: str, box: Box, rng: np.random.Generator) -> np.ndarray:
    """n centres uniformly inside one layer of the box."""
    i = LAYERS.index(layer)
    edges = box.layer_edges()
    z_hi, z_lo = edges[i], edges[i + 1]
    return np.column_stack(
        (
            rng.uniform(box.x0, box.x1, n),
            rng.uniform(box.y0, box.y1, n),
            rng.uniform(z_lo, z_hi - 1e-9, n),
        )
    )


def layered_set(arrangement: dict[str, float], box: Box, seed: int = 1):
    """Particles with one class per layer, equal particle volume in every layer."""
    rng = np.random.default_rng(seed)
    pos, rad = [], []
    for layer, radius in arrangement.items():
        n = EQUAL_VOLUME_COUNTS[radius]
        pos.append(layer_points(n, layer, box, rng))
        rad.append(np.full(n, radius))
    return np.vstack(pos), np.concatenate(rad)


def mixed_set(box: Box, seed: int = 2):
    """Every layer holds the same particles: a third of each class's equal-volume count."""
    rng = np.random.default_rng(seed)
    pos, rad = [], []
    for layer in LAYERS:
        for radius, n in EQUAL_VOLUME_COUNTS.items():
            k = n // 2
            pos.append(layer_points(k, layer, box, rng))
            rad.append(np.full(k, radius))
    return np.vstack(pos), np.concatenate(rad)


def test_assign_classes_maps_radii_and_rejects_strangers():
    idx = assign_classes(np.array([0.5e-3, 1.0e-3, 0.8e-3 * (1 + 1e-9)]), RADII)
    assert idx.tolist() == [2, 0, 1]
    with pytest.raises(ValueError, match=r"0\.0007"):
        assign_classes(np.array([0.7e-3]), RADII)


def test_volumes_recover_a_known_layering_and_ignore_outsiders():
    pos, rad = layered_set({"top": 0.5e-3, "middle": 0.8e-3, "bottom": 1.0e-3}, BOX)
    # outsiders: above the box (the heap), beside it, in front of it
    extra = np.array([[0.01, 0.01, 0.0305], [0.01, -0.001, 0.005], [0.0301, 0.01, 0.005]])
    pos = np.vstack((pos, extra))
    rad = np.concatenate((rad, [1.0e-3, 1.0e-3, 0.5e-3]))
    volumes, counts = layer_class_volumes(pos, rad, BOX, RADII)
    expected_counts = np.array([[0, 0, 512], [0, 125, 0], [64, 0, 0]])
    np.testing.assert_array_equal(counts, expected_counts)
    np.testing.assert_allclose(
        volumes, expected_counts * np.array([sphere_volume(r) for r in RADII]), rtol=1e-12
    )


def test_layer_boundaries_are_half_open():
    box = Box(0.0, 1.0, 0.0, 1.0, 0.0, 3.0)
    z = np.array([0.0, 1.0, 2.0, 2.999, 3.0])
    pos = np.column_stack((np.full(5, 0.5), np.full(5, 0.5), z))
    _, counts = layer_class_volumes(pos, np.full(5, 1e-3), box, [1e-3])
    # z = 1 starts the middle layer, z = 2 the top one, z = 3 is above the box
    np.testing.assert_array_equal(counts[:, 0], [2, 1, 1])


def test_table_fractions_and_shares():
    pos, rad = layered_set({"top": 0.5e-3, "middle": 0.8e-3, "bottom": 1.0e-3}, BOX)
    volumes, counts = layer_class_volumes(pos, rad, BOX, RADII)
    table = layer_table(volumes, counts, RADII, BOX)
    assert len(table) == 9
    by = table.set_index(["layer", "radius"])
    assert by.loc[("bottom", 1.0e-3), "volume_fraction"] == pytest.approx(1.0)
    assert by.loc[("top", 0.5e-3), "share_of_class"] == pytest.approx(1.0)
    assert by.loc[("top", 1.0e-3), "volume_fraction"] == 0.0
    for _, rows in table.groupby("layer"):
        assert rows["volume_fraction"].sum() == pytest.approx(1.0)
    for _, rows in table.groupby("radius"):
        assert rows["share_of_class"].sum() == pytest.approx(1.0)
    assert by.loc[("top", 0.5e-3), "z_low"] == pytest.approx(0.02)
    layer_volume = BOX.volume / 3
    assert by.loc[("middle", 0.8e-3), "solid_fraction"] == pytest.approx(
        125 * sphere_volume(0.8e-3) / layer_volume
    )


def test_index_of_a_fully_sorted_box():
    pos, rad = layered_set({"top": 0.5e-3, "middle": 0.8e-3, "bottom": 1.0e-3}, BOX)
    volumes, _ = layer_class_volumes(pos, rad, BOX, RADII)
    idx = segregation_index(volumes, RADII)
    # equal layer volumes: r_box is the plain mean of the three radii
    assert idx.index == pytest.approx((1.0 - 0.5) / ((1.0 + 0.8 + 0.5) / 3))
    assert idx.normalised == pytest.approx(1.0)
    assert idx.mean_radius["middle"] == pytest.approx(0.8e-3)


def test_index_of_an_inversely_sorted_box_is_minus_one():
    pos, rad = layered_set({"top": 1.0e-3, "middle": 0.8e-3, "bottom": 0.5e-3}, BOX)
    volumes, _ = layer_class_volumes(pos, rad, BOX, RADII)
    idx = segregation_index(volumes, RADII)
    assert idx.normalised == pytest.approx(-1.0)


def test_index_of_a_perfectly_mixed_box_is_zero():
    pos, rad = mixed_set(BOX)
    volumes, counts = layer_class_volumes(pos, rad, BOX, RADII)
    idx = segregation_index(volumes, RADII)
    assert idx.index == pytest.approx(0.0, abs=1e-12)
    assert idx.normalised == pytest.approx(0.0, abs=1e-12)
    table = layer_table(volumes, counts, RADII, BOX)
    np.testing.assert_allclose(table["share_of_class"], 1.0 / 3.0)


def test_index_of_a_random_mixture_is_near_zero():
    rng = np.random.default_rng(5)
    n = 60_000
    radius = rng.choice(RADII, size=n)
    pos = np.column_stack(
        (rng.uniform(0, 0.03, n), rng.uniform(0, 0.02, n), rng.uniform(0, 0.03, n))
    )
    volumes, _ = layer_class_volumes(pos, radius, BOX, RADII)
    idx = segregation_index(volumes, RADII)
    assert abs(idx.normalised) < 0.03
    assert idx.sorted_index > 0.2


def test_sorted_volumes_fill_the_bottom_with_the_coarsest_and_keep_the_sums():
    # layer volumes 2, 3, 5 (top, middle, bottom); class volumes 4 (r 3), 4 (r 2), 2 (r 1)
    volumes = np.array([[1.0, 0.5, 0.5], [1.0, 1.5, 0.5], [2.0, 2.0, 1.0]])
    radii = [3.0, 2.0, 1.0]
    out = sorted_volumes(volumes, radii)
    expected = np.array([[0.0, 0.0, 2.0], [0.0, 3.0, 0.0], [4.0, 1.0, 0.0]])
    np.testing.assert_allclose(out, expected)
    np.testing.assert_allclose(out.sum(axis=0), volumes.sum(axis=0))
    np.testing.assert_allclose(out.sum(axis=1), volumes.sum(axis=1))


def test_mean_radii_of_empty_layers_are_nan():
    per_layer, whole = mean_radii(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), [2.0, 1.0])
    assert math.isnan(per_layer[0])
    assert per_layer[1:].tolist() == [2.0, 1.0]
    assert whole == pytest.approx(1.5)
    assert math.isnan(segregation_index(np.zeros((3, 2)), [2.0, 1.0]).index)


def test_table_volumes_round_trip_through_csv(tmp_path):
    pos, rad = layered_set({"top": 0.8e-3, "middle": 0.5e-3, "bottom": 1.0e-3}, BOX)
    volumes, counts = layer_class_volumes(pos, rad, BOX, RADII)
    path = tmp_path / "t.csv"
    layer_table(volumes, counts, RADII, BOX).to_csv(path, index=False)
    back, radii = table_volumes(pd.read_csv(path))
    order = np.argsort(RADII)
    np.testing.assert_allclose(back, volumes[:, order], rtol=1e-12)
    assert radii == sorted(RADII)
    with pytest.raises(KeyError, match="volume"):
        table_volumes(pd.read_csv(path).drop(columns="volume"), "t.csv")


def moving_snapshots(n_transient: int, n_steady: int, speed: float = 0.01, dt: float = 0.05):
    """A box moving along +x; it fills mixed, then holds a sorted bed that moves with it.

    The particles are given in the fixed frame, so an analysis that did not move the box
    with time would miss them.
    """
    mixed_pos, mixed_rad = mixed_set(BOX, seed=3)
    sorted_pos, sorted_rad = layered_set({"top": 0.5e-3, "middle": 0.8e-3, "bottom": 1.0e-3}, BOX)
    rng = np.random.default_rng(4)
    snaps = []
    for i in range(n_transient + n_steady):
        t = i * dt
        shift = np.array([speed * t, 0.0, 0.0])
        box = Box(BOX.x0 + shift[0], BOX.x1 + shift[0], BOX.y0, BOX.y1, BOX.z0, BOX.z1)
        if i < n_transient:
            keep = rng.random(mixed_rad.size) < (i + 1) / (n_transient + 1)
            pos, rad = mixed_pos[keep], mixed_rad[keep]
        else:
            pos, rad = sorted_pos, sorted_rad
        # a stray particle left behind where the box was at t = 0
        pos = np.vstack((pos + shift, [[0.001, 0.01, 0.005]])) if i > 5 else pos + shift
        rad = np.concatenate((rad, [1.0e-3])) if i > 5 else rad
        snaps.append((t, pos, rad, box))
    return snaps


def test_analysis_follows_the_moving_box_and_averages_the_steady_tail():
    result = analyse_segregation(moving_snapshots(12, 20), RADII, min_fraction=0.2)
    assert result.window.steady
    assert result.window.start_index >= 12
    assert result.window.end_index == 32
    assert result.index.normalised == pytest.approx(1.0)
    by = result.table.set_index(["layer", "radius"])
    assert by.loc[("bottom", 1.0e-3), "n_particles"] == pytest.approx(64)
    assert by.loc[("top", 0.5e-3), "volume_fraction"] == pytest.approx(1.0)
    # the transient is in the record
    assert result.series["segregation_index"].iloc[:12].abs().max() < 0.2


def test_unsteady_record_is_flagged_and_uses_the_last_fraction():
    snaps = moving_snapshots(30, 0)
    series, _, _ = segregation_time_series(snaps, RADII)
    # a steadily rising fill
    window = steady_window(series, min_fraction=0.2)
    assert not window.steady
    assert window.end_index == 30
    assert window.start_index == 30 - 6
    assert "solid_fraction" in window.reason


def test_short_or_empty_records():
    pos, rad = layered_set({"top": 0.5e-3, "middle": 0.8e-3, "bottom": 1.0e-3}, BOX)
    snaps = [(0.1 * i, pos, rad, BOX) for i in range(4)]
    series, volumes, counts = segregation_time_series(snaps, RADII)
    assert volumes.shape == (4, 3, 3) and counts.shape == (4, 3, 3)
    window = steady_window(series)
    assert not window.steady and "10 needed" in window.reason
    empty = [(0.1 * i, np.zeros((0, 3)), np.zeros(0), BOX) for i in range(3)]
    with pytest.raises(ValueError, match="no snapshot"):
        steady_window(segregation_time_series(empty, RADII)[0])


def test_box_rejects_inverted_bounds():
    with pytest.raises(ValueError, match="z0 < z1"):
        Box(0, 1, 0, 1, 1, 0)
