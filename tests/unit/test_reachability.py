"""Is a measured value within the range of the design's parameter sets? (first line of Table 5)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from demcal.core.experiments import load_experiment
from demcal.identification.reachability import edge_sets, reach_of_measurements, reach_statement

DATA = pd.DataFrame(
    {
        "test": ["shear_cell"] * 4 + ["angle_of_repose"] * 3,
        "design_id": ["c0001", "c0002", "c0001", "c0002", "c0001", "c0002", "c0003"],
        "normal_stress": [1068.0, 1068.0, 10070.0, 10070.0] + [float("nan")] * 3,
        "P": [1.0, 1.0, 1.0, 1.0] + [float("nan")] * 3,
        "rho_b": [1400.0, 1500.0, 1650.0, 1720.0] + [float("nan")] * 3,
        "aor": [float("nan")] * 4 + [7.8, 25.0, 33.0],
    }
)


def experiment(tmp_path: Path, rho_b: float, aor: float):
    path = tmp_path / "exp.yaml"
    record = {
        "material": "test fines",
        "angle_of_repose": {"value": aor},
        "shear_cell": [{"normal_stress": 10070, "P": 1.0, "rho_b": rho_b}],
    }
    path.write_text(yaml.safe_dump(record))
    return load_experiment(path)


def test_a_measurement_inside_the_widened_range_is_reachable(tmp_path: Path) -> None:
    # 1760 lies 2.3 % above the largest DEM value at 10 070 Pa, within the 5 % tolerance.
    reach = reach_of_measurements(DATA, experiment(tmp_path, 1760.0, 30.0), tol=0.05)
    assert [r.reachable for r in reach] == [True, True]
    assert [r.inside for r in reach] == [False, True]
    assert (reach[0].dem_min, reach[0].dem_max, reach[0].n_sets) == (1650.0, 1720.0, 2)
    assert reach_statement(reach, "test fines").startswith(
        "**The measurement of test fines lies at the edge"
    )
    inside = reach_of_measurements(DATA, experiment(tmp_path, 1700.0, 30.0), tol=0.05)
    assert [r.inside for r in inside] == [True, True]
    assert reach_statement(inside, "test fines").startswith("Every measured value")


def test_a_measurement_beyond_every_run_but_within_the_tolerance_is_at_the_edge(
    tmp_path: Path,
) -> None:
    # The default study's heaps reach 38.0 deg; the sinter fines' 38.85 is 2.2 % above.
    data = DATA.copy()
    data.loc[6, "aor"] = 38.0
    reach = reach_of_measurements(data, experiment(tmp_path, 1700.0, 38.85), tol=0.05)
    assert [r.reachable for r in reach] == [True, True]
    assert [r.inside for r in reach] == [True, False]
    line = reach_statement(reach, "test fines")
    assert line.startswith("**The measurement of test fines lies at the edge")
    assert "aor (angle of repose) measured 38.85, above every parameter set" in line
    assert "(7.8 to 38, means" in line and "rho_b" not in line and "\n" not in line


def test_the_first_line_names_what_cannot_be_reached(tmp_path: Path) -> None:
    # The sinter fines' 38.85 deg against quick heaps of 7.8-33 deg; rho_b below the range.
    reach = reach_of_measurements(DATA, experiment(tmp_path, 1500.0, 38.85), tol=0.05)
    assert [r.reachable for r in reach] == [False, False]
    line = reach_statement(reach, "test fines")
    assert line.startswith("**The model cannot reach the measurement of test fines**")
    assert (
        "aor (angle of repose) measured 38.85, parameter sets of the design box 7.8 to 33" in line
    )
    assert "rho_b" in line and "1650 to 1720" in line
    assert "\n" not in line


def test_a_condition_without_runs_is_not_reachable(tmp_path: Path) -> None:
    no_aor = DATA[DATA["test"] == "shear_cell"]
    reach = reach_of_measurements(no_aor, experiment(tmp_path, 1700.0, 30.0), tol=0.05)
    assert reach[1].n_sets == 0 and not reach[1].reachable
    assert "no DEM run of the design has a value" in reach_statement(reach, "x")


def heap_data(above: list[float]) -> pd.DataFrame:
    """The shear runs of DATA and 64 heaps: 9-38 deg, then ``above``."""
    heaps = [*np.linspace(9.0, 38.0, 64 - len(above)).tolist(), *above]
    ids = [f"h{k:03d}" for k in range(len(heaps))]
    aor = pd.DataFrame({"test": "angle_of_repose", "design_id": ids, "aor": heaps})
    return pd.concat([DATA[DATA["test"] == "shear_cell"], aor], ignore_index=True)


def test_a_value_only_a_few_runs_reach_lies_at_the_edge(tmp_path: Path) -> None:
    # 64 heaps as in the default study: the sinter fines' 38.85 deg with two heaps above it
    # (39.3, 39.5: one seed's scatter) is at the edge; with four above (6 %) it is inside.
    measured = experiment(tmp_path, 1700.0, 38.85)
    reach = reach_of_measurements(heap_data([39.3, 39.5]), measured, tol=0.05)
    aor = reach[1]
    assert (aor.n_sets, aor.n_beyond, aor.above, aor.reachable, aor.inside) == (
        64,
        2,
        True,
        True,
        False,
    )
    line = reach_statement(reach, "test fines")
    assert line.startswith("**The measurement of test fines lies at the edge")
    assert "aor (angle of repose) measured 38.85, above 62 of the 64 parameter sets" in line
    more = reach_of_measurements(heap_data([39.0, 39.1, 39.3, 39.5]), measured, tol=0.05)
    assert more[1].n_beyond == 4 and more[1].inside
    assert reach_statement(more, "test fines").startswith("Every measured value")


def test_the_far_side_of_a_low_value_is_below_it(tmp_path: Path) -> None:
    # rho_b 1655 lies below the median of 1650 / 1720 with one run below it: inside for two runs.
    reach = reach_of_measurements(DATA, experiment(tmp_path, 1655.0, 30.0), tol=0.05)
    assert (reach[0].above, reach[0].n_beyond, reach[0].inside) == (False, 1, True)
    below = reach_of_measurements(DATA, experiment(tmp_path, 1600.0, 30.0), tol=0.05)
    assert (below[0].n_beyond, below[0].inside, below[0].reachable) == (0, False, True)
    assert (
        "rho_b (normal_stress=10070,P=1) measured 1600, below every parameter set"
        in reach_statement(below, "x")
    )


def test_replicate_runs_count_as_their_set_mean(tmp_path: Path) -> None:
    # Two heaps of one set at 36.5 and 40.3 deg: one run above the measured 38.85 deg, but the
    # set (38.4 deg on average) is not; seed scatter alone does not put the value in reach.
    data = heap_data([39.0, 39.1, 39.3])
    heap = pd.DataFrame({"test": "angle_of_repose", "design_id": "h999", "aor": [36.5, 40.3]})
    data = pd.concat([data, heap], ignore_index=True)
    measured = experiment(tmp_path, 1700.0, 38.85)
    aor = reach_of_measurements(data, measured, tol=0.05)[1]
    assert (aor.n_sets, aor.n_beyond, aor.inside, aor.dem_max) == (65, 3, False, 39.3)
    one = data.assign(design_id=[f"r{k}" for k in range(len(data))])
    runs = reach_of_measurements(one, measured, tol=0.05)[1]
    assert (runs.n_sets, runs.n_beyond, runs.inside, runs.dem_max) == (66, 4, True, 40.3)
    # Shear runs of one set at the same condition (replicates) are averaged as well.
    rho = reach_of_measurements(DATA.assign(design_id="c0001"), measured, tol=0.05)[0]
    assert (rho.n_sets, rho.dem_min, rho.dem_max) == (1, 1685.0, 1685.0)


def test_the_edge_needs_five_per_cent_of_the_sets() -> None:
    assert [edge_sets(n) for n in (1, 12, 20, 21, 64, 100)] == [1, 1, 1, 2, 4, 5]
