"""Tests of Table 5, the identified parameters, the dominant-COR map and the figures."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from demcal.identification.figures import box_plot_normalised, cor_density_plot
from demcal.identification.statistics import (
    combine_statistics,
    dominant_bin_map,
    identified_parameters,
    read_table5_csv,
    table5_markdown,
    valid_set_statistics,
    write_table5_csv,
    write_table5_markdown,
)
from tests.figures import colour_mask, read_png, saved_figures

RANGES = {
    "coefficientFriction": (0.1, 1.0),
    "coefficientRollingFriction": (0.1, 1.0),
    "coefficientRestitution": (0.5, 0.9),
    "density": (2500.0, 3500.0),
}


def hand_set() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "coefficientFriction": [0.2, 0.4, 0.6],
            "coefficientRollingFriction": [0.5, 0.5, 0.8],
            "coefficientRestitution": [0.6, 0.7, 0.8],
            "density": [2600.0, 2800.0, 3000.0],
            "mu_psh": [0.6, 0.61, 0.59],
        }
    )


def test_valid_set_statistics_hand_computed() -> None:
    table = valid_set_statistics(hand_set(), RANGES, n_total=200, label="SSC")
    col = table["SSC"]
    assert col[("coefficientFriction", "mean")] == pytest.approx(0.4)
    assert col[("coefficientFriction", "sd")] == pytest.approx(0.2)  # sample sd, ddof=1
    assert col[("coefficientFriction", "max")] == pytest.approx(0.6)
    assert col[("coefficientFriction", "range")] == pytest.approx(0.9)
    assert col[("coefficientFriction", "sd/range")] == pytest.approx(0.2 / 0.9)
    assert col[("coefficientRollingFriction", "mean")] == pytest.approx(0.6)
    assert col[("coefficientRollingFriction", "sd")] == pytest.approx(math.sqrt(0.03))
    assert col[("coefficientRestitution", "range")] == pytest.approx(0.4)
    assert col[("coefficientRestitution", "sd/range")] == pytest.approx(0.1 / 0.4)
    assert col[("density", "mean")] == pytest.approx(2800.0)
    assert col[("density", "sd/range")] == pytest.approx(0.2)
    assert col[("valid sets", "number")] == 3
    assert col[("valid sets", "percent")] == pytest.approx(1.5)
    assert len(table) == 4 * 5 + 2
    assert "mu_psh" not in table.index.get_level_values("parameter")


def test_valid_set_statistics_few_sets() -> None:
    one = valid_set_statistics(hand_set().iloc[:1], RANGES, n_total=10)["valid"]
    assert one[("density", "mean")] == 2600.0
    assert math.isnan(one[("density", "sd")])
    none = valid_set_statistics(hand_set().iloc[:0], RANGES, n_total=10)["valid"]
    assert none[("valid sets", "number")] == 0
    assert none[("valid sets", "percent")] == 0.0
    assert math.isnan(none[("density", "mean")])
    assert none[("density", "range")] == 1000.0


def test_valid_set_statistics_errors() -> None:
    with pytest.raises(KeyError, match="porosity"):
        valid_set_statistics(hand_set(), {"porosity": (0.0, 1.0)}, n_total=10)
    with pytest.raises(ValueError, match="exceed"):
        valid_set_statistics(hand_set(), RANGES, n_total=2)
    with pytest.raises(ValueError, match="high > low"):
        valid_set_statistics(hand_set(), {"density": (3500.0, 2500.0)}, n_total=10)


def test_combine_statistics_side_by_side() -> None:
    a = valid_set_statistics(hand_set(), RANGES, 100, label="SSC")
    b = valid_set_statistics(hand_set().iloc[1:], RANGES, 100, label="SSC & AoR")
    both = combine_statistics([a, b])
    assert list(both.columns) == ["SSC", "SSC & AoR"]
    assert both.loc[("valid sets", "number"), "SSC & AoR"] == 2
    assert both.loc[("coefficientFriction", "mean"), "SSC & AoR"] == pytest.approx(0.5)
    c = valid_set_statistics(hand_set(), {"density": (2500.0, 3500.0)}, 100, label="x")
    with pytest.raises(ValueError, match="different rows"):
        combine_statistics([a, c])


def test_identified_parameters() -> None:
    ident = identified_parameters(hand_set())
    assert list(ident) == list(RANGES)
    assert ident["density"] == pytest.approx(
        {"mean": 2800.0, "sd": 200.0, "min": 2600.0, "max": 3000.0}
    )
    assert identified_parameters(hand_set().iloc[:1])["density"]["sd"] == 0.0
    with pytest.raises(ValueError, match="no valid sets"):
        identified_parameters(hand_set().iloc[:0])
    with pytest.raises(KeyError, match="porosity"):
        identified_parameters(hand_set(), ["porosity"])


def test_markdown_and_csv_writers(tmp_path: Path) -> None:
    a = valid_set_statistics(hand_set(), RANGES, 200, label="SSC")
    b = valid_set_statistics(hand_set().iloc[:2], RANGES, 200, label="AoR")
    table = combine_statistics([a, b])
    text = table5_markdown(table)
    lines = text.strip().splitlines()
    assert lines[0] == "| parameter | statistic | SSC | AoR |"
    assert len(lines) == 2 + len(table)
    assert "| mu_s (-) | mean | 0.4 | 0.3 |" in lines
    assert "|  | sd/range | 0.2222 | 0.1571 |" in lines
    assert "| valid sets | number | 3 | 2 |" in lines
    assert "|  | percent | 1.50 | 1.00 |" in lines
    md = write_table5_markdown(table, tmp_path / "table5.md")
    assert md.read_text() == text
    csv = write_table5_csv(table, tmp_path / "table5.csv")
    back = read_table5_csv(csv)
    pd.testing.assert_frame_equal(back, table, check_exact=False, rtol=1e-9)
    (tmp_path / "bad.csv").write_text("a,b\n1,2\n")
    with pytest.raises(KeyError, match=r"bad\.csv.*parameter"):
        read_table5_csv(tmp_path / "bad.csv")


def test_dominant_bin_map_hand_made() -> None:
    axes = {
        "coefficientFriction": (0.0, 1.0),
        "coefficientRollingFriction": (0.0, 1.0),
        "coefficientRestitution": (0.5, 0.9),
    }
    # Cells: 2 x 2 over [0, 1]^2; COR bins: [0.5, 0.6, 0.7, 0.8, 0.9].
    valid = pd.DataFrame(
        {
            "coefficientFriction": [0.1, 0.2, 0.3, 1.0, 0.75, 0.9, 0.6, 0.6],
            "coefficientRollingFriction": [0.1, 0.3, 0.4, 1.0, 0.75, 0.2, 0.2, 0.2],
            "coefficientRestitution": [0.55, 0.58, 0.85, 0.9, 0.85, 0.65, 0.75, 0.74],
        }
    )
    m = dominant_bin_map(valid, axes, n_cells=2, n_bins=4)
    np.testing.assert_allclose(m.bin_edges, [0.5, 0.6, 0.7, 0.8, 0.9])
    np.testing.assert_allclose(m.x_edges, [0.0, 0.5, 1.0])
    # Rows are mu_r cells, columns mu_s cells; the upper edge (1.0, 0.9) joins the last cell/bin.
    np.testing.assert_array_equal(m.dominant, [[0, 2], [-1, 3]])
    np.testing.assert_array_equal(m.counts[0, 0], [2, 0, 0, 1])
    np.testing.assert_array_equal(m.counts[0, 1], [0, 1, 2, 0])
    np.testing.assert_array_equal(m.counts[1, 1], [0, 0, 0, 2])
    assert m.counts.sum() == len(valid)


def test_dominant_bin_map_tie_and_axis_arrays() -> None:
    axes = {
        "coefficientFriction": np.array([0.1, 0.4, 1.0]),
        "coefficientRollingFriction": np.array([0.1, 1.0]),
        "coefficientRestitution": np.array([0.5, 0.62, 0.9]),
    }
    valid = pd.DataFrame(
        {
            "coefficientFriction": [0.5, 0.5],
            "coefficientRollingFriction": [0.5, 0.5],
            "coefficientRestitution": [0.85, 0.55],
        }
    )
    m = dominant_bin_map(valid, axes, n_cells=(3, 1), n_bins=4)
    assert m.dominant.shape == (1, 3)
    np.testing.assert_array_equal(m.dominant, [[-1, 0, -1]])  # tie -> lowest COR range
    outside = valid.assign(coefficientFriction=[1.2, 0.5])
    with pytest.raises(ValueError, match="coefficientFriction"):
        dominant_bin_map(outside, axes, n_cells=3)
    with pytest.raises(KeyError, match="coefficientRestitution"):
        dominant_bin_map(valid, {k: v for k, v in axes.items() if k != "coefficientRestitution"})


def test_box_plot_shows_each_parameter_over_its_maximum(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    valid = pd.DataFrame(
        {
            "coefficientFriction": rng.uniform(0.6, 0.9, 200),
            "coefficientRollingFriction": rng.uniform(0.1, 1.0, 200),
            "coefficientRestitution": rng.uniform(0.5, 0.9, 200),
            "density": rng.uniform(2200.0, 2400.0, 200),
        }
    )
    with saved_figures() as figures:
        out = box_plot_normalised(valid, tmp_path / "fig6.png", "SSC, 10070 Pa, P = 1")
    ((ax,),) = [f.axes for f in figures]
    labels = [t.get_text() for t in ax.get_xticklabels()]
    assert labels == ["mu_s (-)", "mu_r (-)", "COR (-)", "rho_p (kg/m^3)"]
    assert ax.get_title() == "SSC, 10070 Pa, P = 1 (200 valid sets)"
    # One box per parameter at x = 1..4: quartiles and median of the column over its maximum.
    boxes = [line for line in ax.lines if len(line.get_xdata()) == 5]
    medians = [
        line for line in ax.lines if len(line.get_xdata()) == 2 and np.ptp(line.get_xdata()) > 0.4
    ]
    assert len(boxes) == len(medians) == 4
    for k, name in enumerate(valid.columns):
        scaled = valid[name] / valid[name].max()
        box, median = boxes[k], medians[k]
        assert np.mean([min(box.get_xdata()), max(box.get_xdata())]) == pytest.approx(k + 1)
        q1, q3 = np.percentile(scaled, [25, 75])
        assert (min(box.get_ydata()), max(box.get_ydata())) == pytest.approx((q1, q3))
        assert median.get_ydata()[0] == pytest.approx(np.median(scaled))
    # Every value is at most its maximum: nothing is drawn above 1.
    assert max(max(line.get_ydata(), default=0.0) for line in ax.lines) == pytest.approx(1.0)
    assert read_png(out).shape == (480, 660, 3)  # 5.5 x 4 in at 120 dpi
    with pytest.raises(ValueError, match="no valid sets"):
        box_plot_normalised(valid.iloc[:0], tmp_path / "empty.png", "empty")
    with pytest.raises(KeyError, match="porosity"):
        box_plot_normalised(valid, tmp_path / "x.png", "x", parameters=["porosity"])


def test_cor_density_plot_colours_each_cell_by_its_dominant_cor_range(tmp_path: Path) -> None:
    rng = np.random.default_rng(1)
    n = 500
    mu_s = rng.uniform(0.1, 1.0, n)
    valid = pd.DataFrame(
        {
            "coefficientFriction": mu_s,
            "coefficientRollingFriction": np.clip(1.1 - mu_s + rng.normal(0, 0.05, n), 0.1, 1.0),
            "coefficientRestitution": 0.5 + 0.4 * (mu_s - 0.1) / 0.9,
        }
    )
    axes = {k: v for k, v in RANGES.items() if k != "density"}
    with saved_figures() as figures:
        out = cor_density_plot(valid, axes, tmp_path / "fig7.png", n_cells=15)
    ((ax,),) = [f.axes for f in figures]
    expected = dominant_bin_map(valid, axes, n_cells=15, n_bins=4).dominant
    (mesh,) = ax.collections
    shown = np.ma.asarray(mesh.get_array()).reshape(expected.shape)
    np.testing.assert_array_equal(shown.mask, expected < 0)
    np.testing.assert_array_equal(shown.filled(-1), expected)
    # A band along mu_r = 1.1 - mu_s: COR rises with mu_s, so all four ranges show.
    assert set(np.unique(expected)) == {-1, 0, 1, 2, 3}
    assert (ax.get_xlim(), ax.get_ylim()) == ((0.1, 1.0), (0.1, 1.0))
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == ["COR 0.50-0.60", "COR 0.60-0.70", "COR 0.70-0.80", "COR 0.80-0.90"]
    image = read_png(out)
    assert image.shape == (576, 660, 3)  # 5.5 x 4.8 in at 120 dpi
    # The empty cells stay white: a band of coloured cells on a white field.
    assert colour_mask(image, "white").mean() > 0.2
    assert (image.max(axis=2) - image.min(axis=2) > 0.3).mean() > 0.01
