"""The mu(t) figure of a shear-cell run: what it draws, on a synthetic run with known windows.

A tiny four-cycle case is rendered (``render_case``) and given a print table in which mu rises
through a transient at the start of every pre-shear and shear phase before it levels off
(cycle 3's shear keeps rising and is not steady). The figure must shade exactly the windows the
readout averaged (not the whole phases), draw their means and say which are steady.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgb

from demcal.bulk.values import extract
from demcal.engine_io.fix_output import read_print_file
from demcal.virtual_tests.deck import render_case
from demcal.virtual_tests.pictures import mu_series_figure
from tests.figures import colour_mask, read_png, saved_figures
from tests.unit.test_decks import CASE, tiny, write_shear_table

MU_PSH, MU_SH = 0.62, 0.55
COLOURS = {"psh": "tab:blue", "sh": "tab:orange"}


def add_transients(case_dir: Path, seed: int = 3) -> None:
    """Rewrite the shear force of the print table so that mu has a start-up transient.

    In every pre-shear and shear phase mu rises as ``1 - 0.6 exp(-(t - t0) / (0.08 T))`` of
    its level (T the phase duration) with 1 % noise; the shear of cycle 3 instead ramps
    linearly from half its level to the end.
    """
    path = case_dir / json.loads((case_dir / "case.json").read_text())["files"]["table"]
    table = read_print_file(path)
    rng = np.random.default_rng(seed)
    shear = table["shear_force"].to_numpy(dtype=np.float64).copy()
    for (cycle, phase), rows in table.groupby(["cycle", "phase"]):
        if phase not in (1, 3):
            continue
        t = rows["time"].to_numpy(dtype=np.float64)
        elapsed = (t - t[0]) / (t[-1] - t[0])
        if (cycle, phase) == (3, 3):
            factor = 0.5 + 0.5 * elapsed
        else:
            factor = 1.0 - 0.6 * np.exp(-elapsed / 0.08)
        factor = factor * (1.0 + 0.01 * rng.standard_normal(t.size))
        shear[rows.index] = shear[rows.index] * factor
    table["shear_force"] = shear
    lines = ["# " + " ".join(table.columns)]
    for row in table.itertuples(index=False):
        lines.append(" ".join(str(int(v)) if k == 0 else repr(float(v)) for k, v in enumerate(row)))
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def case(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("mu_series") / "c0007"
    render_case("shear_cell", CASE, tiny(), directory)
    write_shear_table(directory, mu_psh=MU_PSH, mu_sh=MU_SH, rho_b=1450.0)
    add_transients(directory)
    return directory


@pytest.fixture(scope="module")
def drawn(case: Path, tmp_path_factory: pytest.TempPathFactory):
    """(figure, png path, readout values, phase time spans) of one call."""
    png = tmp_path_factory.mktemp("pictures") / "sub" / "mu_series.png"
    with saved_figures() as figures:
        returned = mu_series_figure(case, png)
    assert returned == png and len(figures) == 1 and figures.paths == [png]
    table = read_print_file(case / "shear_cell.txt")
    spans = table.groupby(["cycle", "phase"])["time"].agg(["min", "max"])
    return figures[0], png, extract("shear_cell", case), spans


def by_gid(figure, kind: str) -> dict[str, object]:
    (ax,) = figure.axes
    artists = [*ax.patches, *ax.lines]
    return {a.get_gid(): a for a in artists if (a.get_gid() or "").startswith(kind + "_")}


def x_extent(patch) -> tuple[float, float]:
    """Data x range of an axvspan (a Rectangle or, in older matplotlib, a Polygon)."""
    x = patch.get_path().transformed(patch.get_patch_transform()).vertices[:, 0]
    return float(x.min()), float(x.max())


def test_synthetic_run_has_the_intended_readout(drawn) -> None:
    _, _, values, _ = drawn
    assert values["mu_psh"].to_numpy() == pytest.approx([MU_PSH] * 4, rel=0.01)
    assert values["mu_sh"].to_numpy()[:3] == pytest.approx([MU_SH] * 3, rel=0.01)
    assert values["steady_psh"].tolist() == [True] * 4
    assert values["steady_sh"].tolist() == [True, True, True, False]


def test_shaded_windows_are_the_readout_windows(drawn) -> None:
    figure, _, values, spans = drawn
    windows = by_gid(figure, "window")
    assert len(windows) == 8
    for _, row in values.iterrows():
        cycle = int(row["cycle"])
        for key, phase in (("psh", 1), ("sh", 3)):
            start, end = row[f"{key}_t_start"], row[f"{key}_t_end"]
            patch = windows[f"window_{key}_{cycle}"]
            assert x_extent(patch) == pytest.approx((start, end), rel=1e-12)
            assert to_rgb(patch.get_facecolor()) == pytest.approx(to_rgb(COLOURS[key]))
            # The readout's window, not the phase: the transient before it is left out.
            t0, t1 = spans.loc[(cycle, phase)]
            assert t0 + 0.1 * (t1 - t0) < start < end == pytest.approx(t1)


def test_means_are_drawn_across_the_windows_and_labelled(drawn) -> None:
    figure, _, values, _ = drawn
    means = by_gid(figure, "mean")
    (ax,) = figure.axes
    labels = [t.get_text() for t in ax.texts]
    assert len(means) == 8 and len(labels) == 8
    for _, row in values.iterrows():
        for key in ("psh", "sh"):
            line = means[f"mean_{key}_{int(row['cycle'])}"]
            assert list(line.get_xdata()) == pytest.approx(
                [row[f"{key}_t_start"], row[f"{key}_t_end"]]
            )
            assert list(line.get_ydata()) == pytest.approx([row[f"mu_{key}"]] * 2)
            verdict = "steady" if row[f"steady_{key}"] else "not steady"
            assert f"{row[f'mu_{key}']:.3f}\n{verdict}" in labels
    assert sum("not steady" in text for text in labels) == 1


def test_series_are_the_phases_in_two_colours(drawn, case: Path) -> None:
    figure, _, _, spans = drawn
    series = by_gid(figure, "series")
    assert len(series) == 8
    for key, phase in (("psh", 1), ("sh", 3)):
        for cycle in range(4):
            line = series[f"series_{key}_{cycle}"]
            assert to_rgb(line.get_color()) == pytest.approx(to_rgb(COLOURS[key]))
            t = np.asarray(line.get_xdata(), dtype=float)
            assert (t.min(), t.max()) == pytest.approx(tuple(spans.loc[(cycle, phase)]))
    # The pre-shear levels off at MU_PSH.
    tail = np.asarray(series["series_psh_0"].get_ydata(), dtype=float)[-20:]
    assert tail.mean() == pytest.approx(MU_PSH, rel=0.02)


def test_title_and_axis_labels(drawn) -> None:
    figure, _, _, _ = drawn
    (ax,) = figure.axes
    assert ax.get_title() == "case c0007: mu(t), normal stress 2029 Pa, P = 0.4, 0.6, 0.8, 1"
    assert ax.get_xlabel() == "time (s)"
    assert "(-)" in ax.get_ylabel() and "mu" in ax.get_ylabel()


def test_png_shows_the_shading_at_the_windows(drawn) -> None:
    figure, png, values, spans = drawn
    image = read_png(png)
    height = image.shape[0]
    assert image.shape[1] == pytest.approx(figure.get_figwidth() * figure.dpi)
    (ax,) = figure.axes
    # A row near the bottom of the axes, below every mu curve: only the shading is there.
    row = round(height - ax.transAxes.transform((0.0, 0.03))[1])

    def column(t: float) -> int:
        return round(ax.transData.transform((t, 0.0))[0])

    for _, r in values.iterrows():
        cycle = int(r["cycle"])
        for key, phase in (("psh", 1), ("sh", 3)):
            tint = 0.8 * np.ones(3) + 0.2 * np.asarray(to_rgb(COLOURS[key]))
            shaded = colour_mask(image[row], tuple(tint), tol=0.03)
            c0, c1 = column(r[f"{key}_t_start"]), column(r[f"{key}_t_end"])
            assert shaded[c0 + 2 : c1 - 1].mean() > 0.8
            # Not during the transient before the window.
            p0 = column(spans.loc[(cycle, phase), "min"])
            assert c0 - p0 > 6
            assert not shaded[p0 + 1 : c0 - 2].any()


def test_other_tests_and_missing_output_are_refused(tmp_path: Path) -> None:
    from demcal.bulk.values import MissingOutputError

    render_case("angle_of_repose", CASE, tiny(), tmp_path / "aor")
    with pytest.raises(ValueError, match="not 'shear_cell'"):
        mu_series_figure(tmp_path / "aor", tmp_path / "x.png")
    render_case("shear_cell", CASE, tiny(), tmp_path / "ssc")
    with pytest.raises(MissingOutputError, match=r"shear_cell\.txt"):
        mu_series_figure(tmp_path / "ssc", tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()
