"""Shear-cell readouts on synthetic print tables built from a known mu(t), rho_b and load."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from demcal.engine_io.fix_output import read_print_file
from demcal.engine_io.output_errors import MissingColumnError
from demcal.virtual_tests.shear_cell.readout import (
    INTERIOR_MASS_COLUMN,
    REQUIRED_COLUMNS,
    lid_rings,
    overlap_area,
    shear_cell_bulk_values,
    shear_stress_series,
)

R = 0.02  # cell radius, m
Z_FLOOR = 0.0
Z_SHEAR = 0.015
G = 9.81
AREA = np.pi * R**2
V_WALL = 3 * 0.732e-3  # m/s
DT_PRINT = 2e-3  # s
T_PRE = 0.1875 * R / V_WALL  # pre-shear duration, s
T_SHEAR = 0.95 * T_PRE


# ---------------------------------------------------------------------------- overlap area


def test_overlap_area_known_values() -> None:
    assert overlap_area(R, 0.0) == pytest.approx(np.pi * R**2, rel=1e-14)
    # Centres one radius apart: lens area R^2 (2 pi / 3 - sqrt(3) / 2).
    assert overlap_area(R, R) == pytest.approx(R**2 * (2 * np.pi / 3 - np.sqrt(3) / 2), rel=1e-13)
    assert overlap_area(R, -R) == overlap_area(R, R)
    assert overlap_area(R, 2 * R) == 0.0
    assert overlap_area(R, 3 * R) == 0.0
    d = np.linspace(0.0, 2 * R, 11)
    a = overlap_area(R, d)
    assert a.shape == d.shape
    assert np.all(np.diff(a) < 0.0)


def test_overlap_area_matches_grid_count() -> None:
    n = 1601
    x = np.linspace(-R, 3 * R, n)
    y = np.linspace(-R, R, n // 2)
    cell = (x[1] - x[0]) * (y[1] - y[0])
    xx, yy = np.meshgrid(x, y)
    in_first = xx**2 + yy**2 <= R**2
    for d in (0.1 * R, 0.73 * R, 1.5 * R):
        count = np.count_nonzero(in_first & ((xx - d) ** 2 + yy**2 <= R**2))
        assert overlap_area(R, d) == pytest.approx(count * cell, rel=3e-3)


def test_overlap_area_slope_is_minus_chord_length() -> None:
    # dA/dd = -(chord of the lens) = -sqrt(4R^2 - d^2).
    for d in (0.2 * R, R, 1.7 * R):
        h = 1e-7 * R
        slope = (overlap_area(R, d + h) - overlap_area(R, d - h)) / (2 * h)
        assert slope == pytest.approx(-np.sqrt(4 * R**2 - d**2), rel=1e-6)


def test_overlap_area_rejects_bad_radius() -> None:
    with pytest.raises(ValueError, match="radius"):
        overlap_area(0.0, 0.01)


# ------------------------------------------------------------------------ synthetic run


def _phase_times(t0: float, duration: float) -> np.ndarray:
    return t0 + np.arange(0.0, duration, DT_PRINT)


def synthetic_run(
    cycles: list[dict[str, float]],
    seed: int = 0,
    stop_time: float | None = None,
) -> pd.DataFrame:
    """Print table of a shear-cell run whose mu(t) is known.

    Each cycle dict holds normal_stress (Pa), P, mu_psh, mu_sh and rho_b (kg/m^3). The mass in
    the cell is fixed; a cycle's rho_b sets its lid height. The shear force is built as mu(t)
    times the normal force across the shear plane (lid force + weight above the plane + the
    upper tube's and the lower flange's vertical forces), so the readout must return mu(t) up
    to the added noise.
    """
    rng = np.random.default_rng(seed)
    mass = 1760.0 * AREA * 0.03
    parts = []
    settle = _phase_times(0.0, 0.1)
    target0 = cycles[0]["normal_stress"] * AREA
    parts.append(
        pd.DataFrame(
            {
                "time": settle,
                "phase": 0,
                "cycle": 0,
                "lid_z": 0.031,
                "lid_force": 0.9 * target0,
                "shear_force": 0.0,
                "travel": 0.0,
                "target_force": target0,
                "upper_force_z": 0.0,
                "lower_flange_force_z": 0.0,
            }
        )
    )
    t = settle[-1] + DT_PRINT
    for c, spec in enumerate(cycles):
        lid_height = Z_FLOOR + mass / (spec["rho_b"] * AREA)
        target = spec["normal_stress"] * AREA
        t_start = t
        for phase, duration, load, level in (
            (1, T_PRE, target, spec["mu_psh"]),
            (2, 0.05, 0.001 * target, 0.0),
            (3, T_SHEAR, spec["P"] * target, spec["mu_sh"]),
        ):
            times = _phase_times(t, duration)
            n = times.size
            lid_z = lid_height + 2e-6 * rng.standard_normal(n)
            lid_force = load * (1.0 + 0.02 * rng.standard_normal(n))
            weight = mass * G * (lid_z - Z_SHEAR) / (lid_z - Z_FLOOR)
            # A dilating bed held down by the upper tube's friction, a small load on the
            # uncovered flange: the normal force across the plane is not the lid force.
            upper_z = 0.4 * lid_force * (phase != 2)
            flange_z = -0.03 * lid_force * (phase != 2)
            if phase == 2:
                mu = np.zeros(n)
                travel = np.full(n, -V_WALL * (times[0] - t_start))
            else:
                # Rise with time constant 0.1 s, then noise about the level.
                mu = level * (1.0 - np.exp(-(times - t) / 0.1)) + 0.01 * rng.standard_normal(n)
                travel = -V_WALL * (times - t_start)
            parts.append(
                pd.DataFrame(
                    {
                        "time": times,
                        "phase": phase,
                        "cycle": c,
                        "lid_z": lid_z,
                        "lid_force": lid_force,
                        "shear_force": -mu * (lid_force + weight + upper_z + flange_z),
                        "travel": travel,
                        "target_force": load,
                        "upper_force_z": upper_z,
                        "lower_flange_force_z": flange_z,
                    }
                )
            )
            t = times[-1] + DT_PRINT
    table = pd.concat(parts, ignore_index=True)
    table["mass"] = mass
    table.insert(0, "step", np.round(table["time"] / 1e-6).astype(np.int64))
    if stop_time is not None:
        table = table[table["time"] <= stop_time].reset_index(drop=True)
    return table


CYCLES = [
    {"normal_stress": 2029.0, "P": 0.6, "mu_psh": 0.55, "mu_sh": 0.42, "rho_b": 1760.0},
    {"normal_stress": 2029.0, "P": 1.0, "mu_psh": 0.57, "mu_sh": 0.56, "rho_b": 1790.0},
]


def one_row(lid_z: float, lid_force: float, **columns: float) -> pd.DataFrame:
    """A one-row pre-shear table at a lid target of 10 N with the given columns."""
    base = {"time": 1.0, "phase": 1, "cycle": 0, "lid_z": lid_z, "lid_force": lid_force}
    return pd.DataFrame({k: [v] for k, v in {**base, "target_force": 10.0, **columns}.items()})


def test_stress_series_by_hand() -> None:
    # One row with round numbers: rho_b = 1500 kg/m^3 by construction.
    lid_z, travel, lid_force, shear = 0.03, 0.004, 10.0, -6.0
    upper_z, flange_z = 2.5, -0.5
    row = one_row(
        lid_z,
        lid_force,
        shear_force=shear,
        travel=travel,
        mass=1500.0 * AREA * lid_z,
        upper_force_z=upper_z,
        lower_flange_force_z=flange_z,
    )
    out = shear_stress_series(row, R, Z_FLOOR, Z_SHEAR, G).iloc[0]
    area = 2 * R**2 * np.arccos(travel / (2 * R)) - travel / 2 * np.sqrt(4 * R**2 - travel**2)
    weight = 1500.0 * G * AREA * (lid_z - Z_SHEAR)
    assert out["rho_b"] == pytest.approx(1500.0, rel=1e-12)
    assert out["area"] == pytest.approx(area, rel=1e-12)
    normal = lid_force + weight + upper_z + flange_z
    assert out["sigma"] == pytest.approx(normal / area, rel=1e-12)
    assert out["tau"] == pytest.approx(6.0 / area, rel=1e-12)
    assert out["mu"] == pytest.approx(6.0 / normal, rel=1e-12)


def test_bulk_values_recovered_per_cycle() -> None:
    table = synthetic_run(CYCLES, seed=1)
    got = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G)
    assert list(got["cycle"]) == [0, 1]
    for (_, row), spec in zip(got.iterrows(), CYCLES, strict=True):
        assert row["P"] == pytest.approx(spec["P"], rel=1e-12)
        assert row["normal_stress"] == pytest.approx(spec["normal_stress"], rel=1e-12)
        assert row["mu_psh"] == pytest.approx(spec["mu_psh"], abs=0.005)
        assert row["mu_sh"] == pytest.approx(spec["mu_sh"], abs=0.005)
        assert row["rho_b"] == pytest.approx(spec["rho_b"], rel=1e-3)
        assert row["steady_psh"] and row["steady_sh"]
        # The plateau excludes the rise (time constant 0.1 s) and runs to the phase end.
        pre = table[(table["cycle"] == row["cycle"]) & (table["phase"] == 1)]["time"]
        assert row["psh_t_start"] > pre.iloc[0] + 0.3
        assert row["psh_t_end"] == pytest.approx(pre.iloc[-1])
        assert row["mu_psh_sem"] < 0.003


def test_weight_of_the_column_enters_sigma() -> None:
    # Ignoring gravity in the readout raises mu by N / (N - weight), N the normal force across
    # the plane (lid force 1 + 0.4 - 0.03 of it from the walls, see synthetic_run, + weight).
    table = synthetic_run(CYCLES[:1], seed=2)
    with_g = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G)
    without_g = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, g=0.0)
    weight = 1760.0 * G * AREA * (0.03 - Z_SHEAR)
    walls = 1.37 * 2029.0 * AREA
    ratio = without_g["mu_psh"].iloc[0] / with_g["mu_psh"].iloc[0]
    assert ratio == pytest.approx((walls + weight) / walls, rel=2e-3)


def test_upper_tube_force_enters_sigma() -> None:
    # A readout from lid force and weight alone overstates mu by N / (lid + weight) when the
    # upper tube holds a dilating bed down.
    table = synthetic_run(CYCLES[:1], seed=2)
    got = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G)
    assert got["mu_psh"].iloc[0] == pytest.approx(CYCLES[0]["mu_psh"], abs=0.01)
    no_walls = table.assign(upper_force_z=0.0, lower_flange_force_z=0.0)
    naive = shear_cell_bulk_values(no_walls, R, Z_FLOOR, Z_SHEAR, G)
    assert naive["mu_psh"].iloc[0] > 1.3 * CYCLES[0]["mu_psh"]


def test_a_ringing_lid_does_not_raise_mu() -> None:
    # A servo lid that rings: its force swings by +-60 % from one few-row stretch to the next
    # while the bed carries a steady shear force (the quick ring at 1 068 Pa with mu_s 0.1
    # read 0.49-0.87 by the mean of tau / sigma where its contacts gave 0.37-0.42). The readout
    # is mean tau over mean sigma, which the swing leaves alone; the mean of the ratio does not.
    table = synthetic_run(CYCLES[:1], seed=6)
    pre = np.flatnonzero(table["phase"].to_numpy() == 1)
    swing = np.where((np.arange(pre.size) // 3) % 2 == 0, 1.6, 0.4)
    table.loc[pre, "lid_force"] = table.loc[pre, "lid_force"].to_numpy() * swing
    got = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G).iloc[0]
    assert got["steady_psh"]
    series = shear_stress_series(table, R, Z_FLOOR, Z_SHEAR, G)
    window = series[
        (series["phase"] == 1)
        & (series["time"] >= got["psh_t_start"])
        & (series["time"] <= got["psh_t_end"])
    ]
    assert got["mu_psh"] == pytest.approx(window["tau"].mean() / window["sigma"].mean(), rel=1e-12)
    assert window["mu"].mean() > 1.1 * CYCLES[0]["mu_psh"]
    # The steady stretch's own mu: the shear force was built on the unswung normal force, whose
    # mean the swing keeps to within the rows' pairing.
    assert got["mu_psh"] == pytest.approx(CYCLES[0]["mu_psh"], rel=0.03)
    assert 0.0 < got["mu_psh_sem"] < 0.01
    # The shear phase, whose lid did not ring, reads as before.
    assert got["mu_sh"] == pytest.approx(CYCLES[0]["mu_sh"], abs=0.005)


def test_a_lid_alternating_between_print_steps_is_flagged() -> None:
    # A servo oscillating at every time step, printed at an odd interval: the lid force
    # alternates between two values from one row to the next (quick ring, 1 068 Pa, mu_s 0.1:
    # by 70-90 % of its mean). The flag marks that phase only; a slow swing or noise does not
    # count, and the values are the ratio of means as before.
    table = synthetic_run(CYCLES[:1], seed=6)
    quiet = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G).iloc[0]
    assert not quiet["psh_lid_rings"] and not quiet["sh_lid_rings"]
    pre = np.flatnonzero(table["phase"].to_numpy() == 1)
    alternate = np.where(np.arange(pre.size) % 2 == 0, 1.7, 0.3)
    table.loc[pre, "lid_force"] = table.loc[pre, "lid_force"].to_numpy() * alternate
    got = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G).iloc[0]
    assert got["psh_lid_rings"] and not got["sh_lid_rings"]
    assert got["steady_psh"]
    assert got["mu_psh"] == pytest.approx(CYCLES[0]["mu_psh"], rel=0.03)
    rng = np.random.default_rng(1)
    force = 3.0 * (1.0 + 0.02 * rng.standard_normal(200))
    assert not lid_rings(force)
    assert lid_rings(force * np.where(np.arange(200) % 2 == 0, 1.5, 0.5))
    # Alternating by a few per cent only (print noise at a quiet lid) is no ringing.
    assert not lid_rings(3.0 * np.where(np.arange(200) % 2 == 0, 1.05, 0.95))
    # A swing over several rows (period 6) is not an alternation.
    assert not lid_rings(3.0 * np.where((np.arange(200) // 3) % 2 == 0, 1.6, 0.4))
    assert not lid_rings(np.array([1.0, 2.0, 1.0])) and not lid_rings(np.zeros(10))


def test_interrupted_run_flags_unsteady_and_missing_phases() -> None:
    spec = {"normal_stress": 10070.0, "P": 0.8, "mu_psh": 0.5, "mu_sh": 0.45, "rho_b": 1800.0}
    full = synthetic_run([spec, spec], seed=3)
    shear1 = full[(full["cycle"] == 1) & (full["phase"] == 3)]["time"]
    # Stop 0.08 s into the shear of cycle 1: mu is still rising (time constant 0.1 s).
    cut = synthetic_run([spec, spec], seed=3, stop_time=float(shear1.iloc[0]) + 0.08)
    got = shear_cell_bulk_values(cut, R, Z_FLOOR, Z_SHEAR, G)
    assert got["steady_psh"].tolist() == [True, True]
    assert got["steady_sh"].tolist() == [True, False]
    assert got["mu_sh"].iloc[1] < 0.45 * 0.8
    # Stopped during the unload of cycle 1: no shear phase at all.
    unload1 = full[(full["cycle"] == 1) & (full["phase"] == 2)]["time"]
    cut2 = synthetic_run([spec, spec], seed=3, stop_time=float(unload1.iloc[2]))
    got2 = shear_cell_bulk_values(cut2, R, Z_FLOOR, Z_SHEAR, G)
    assert np.isnan(got2["mu_sh"].iloc[1])
    assert np.isnan(got2["P"].iloc[1])
    assert not got2["steady_sh"].iloc[1]
    assert got2["sh_reason"].iloc[1] == "no shear phase"
    assert got2["mu_psh"].iloc[1] == pytest.approx(0.5, abs=0.005)


@pytest.mark.parametrize("share", [-0.3, 0.2, 2.1])
def test_a_phase_whose_load_was_lost_gives_no_value(share: float) -> None:
    # The servo lid of a strongly cohesive bed at low stress: from halfway through the shear
    # of cycle 0 the lid force sits at `share` x the target (as LIGGGHTS and the engine read
    # at 1.16e5 J/m^3 and 1 068 Pa: -1.7 to 0.25 and 2.0 to 3.3), while the pre-shear held it.
    table = synthetic_run(CYCLES, seed=4)
    shear = table[(table["cycle"] == 0) & (table["phase"] == 3)]
    lost = shear.index[len(shear) // 2 :]
    table.loc[lost, "lid_force"] = share * table.loc[lost, "target_force"]
    got = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G)
    assert np.isnan(got["mu_sh"].iloc[0]) and not got["steady_sh"].iloc[0]
    assert got["sh_reason"].iloc[0].startswith("normal load not held: lid force")
    # The pre-shear of the same cycle and the whole of cycle 1 are read as before.
    assert got["mu_psh"].iloc[0] == pytest.approx(CYCLES[0]["mu_psh"], abs=0.005)
    assert got["rho_b"].iloc[0] == pytest.approx(CYCLES[0]["rho_b"], rel=1e-3)
    assert got["mu_sh"].iloc[1] == pytest.approx(CYCLES[1]["mu_sh"], abs=0.005)


def test_a_lost_pre_shear_load_gives_no_density_either() -> None:
    table = synthetic_run(CYCLES[:1], seed=5)
    pre = table["phase"] == 1
    table.loc[pre, "lid_force"] = 1.6 * table.loc[pre, "target_force"]
    got = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G)
    assert np.isnan(got["mu_psh"].iloc[0]) and np.isnan(got["rho_b"].iloc[0])
    assert "1.60 x the target" in got["psh_reason"].iloc[0]
    # Within the band (the tiny cell's sound runs reach 1.35) the value stands.
    table.loc[pre, "lid_force"] = 1.4 * table.loc[pre, "target_force"]
    kept = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G)
    assert np.isfinite(kept["mu_psh"].iloc[0]) and np.isfinite(kept["rho_b"].iloc[0])


def test_from_print_file(tmp_path: Path) -> None:
    table = synthetic_run(CYCLES, seed=4)[["step", *REQUIRED_COLUMNS]]
    path = tmp_path / "shear.print"
    lines = ["# " + " ".join(table.columns)]
    lines += [" ".join(f"{v:.10g}" for v in row) for row in table.to_numpy(dtype=float)]
    path.write_text("\n".join(lines) + "\n")
    from_file = shear_cell_bulk_values(read_print_file(path), R, Z_FLOOR, Z_SHEAR, G)
    direct = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G)
    for col in ("P", "normal_stress", "mu_psh", "mu_sh", "rho_b"):
        np.testing.assert_allclose(from_file[col], direct[col], rtol=1e-6)


def test_plateau_options_are_passed_on() -> None:
    table = synthetic_run(CYCLES[:1], seed=5)
    default = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G)
    strict = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G, min_fraction=0.9)
    # A plateau covering 90 % of the phase would include the rise, so it is not steady; with
    # the default fraction the same pre-shear is.
    assert default["steady_psh"].iloc[0]
    assert not strict["steady_psh"].iloc[0]


def test_bad_tables_raise_clear_errors() -> None:
    table = synthetic_run(CYCLES[:1], seed=6)
    with pytest.raises(MissingColumnError, match="target_force"):
        shear_cell_bulk_values(table.drop(columns="target_force"), R, Z_FLOOR, Z_SHEAR)
    low = table.copy()
    low.loc[low["phase"] == 1, "lid_z"] = Z_SHEAR - 0.001
    with pytest.raises(ValueError, match="lid_z"):
        shear_cell_bulk_values(low, R, Z_FLOOR, Z_SHEAR)
    holes = table.copy()
    holes.loc[5, "lid_force"] = np.nan
    with pytest.raises(ValueError, match="lid_force"):
        shear_cell_bulk_values(holes, R, Z_FLOOR, Z_SHEAR)
    with pytest.raises(ValueError, match="z_shear"):
        shear_cell_bulk_values(table, R, Z_SHEAR, Z_FLOOR)


# ---------------------------------------------------------------------------------------------
# ring cell: torque readout over a fixed annular shear plane

R_IN = 0.01  # inner radius of the ring cell, m
RING_AREA = np.pi * (R**2 - R_IN**2)


def ring_table(table: pd.DataFrame) -> pd.DataFrame:
    """The split-cell synthetic run as the ring prints it: the same normal force across the
    plane, and the torque that a uniform shear stress mu * sigma over the annulus gives."""
    ring = table.drop(columns=["shear_force", "lower_flange_force_z"]).copy()
    # Same solid fraction over the annulus: the mass scales with the cross-section.
    ring["mass"] = table["mass"] * RING_AREA / AREA
    weight = ring["mass"] * G * (ring["lid_z"] - Z_SHEAR) / (ring["lid_z"] - Z_FLOOR)
    normal = ring["lid_force"] + weight + ring["upper_force_z"]
    mu = np.abs(table["shear_force"]) / (
        table["lid_force"]
        + table["mass"] * G * (table["lid_z"] - Z_SHEAR) / (table["lid_z"] - Z_FLOOR)
        + table["upper_force_z"]
        + table["lower_flange_force_z"]
    )
    ring["torque"] = mu * normal / RING_AREA * 2.0 * np.pi * (R**3 - R_IN**3) / 3.0
    return ring


def test_ring_stress_series_by_hand() -> None:
    lid_z, lid_force, upper_z, torque = 0.03, 10.0, 2.5, 0.04
    row = one_row(
        lid_z,
        lid_force,
        torque=-torque,
        travel=0.5,  # arc length at the mean radius: no limit in the ring
        mass=1500.0 * RING_AREA * lid_z,
        upper_force_z=upper_z,
    )
    out = shear_stress_series(row, R, Z_FLOOR, Z_SHEAR, G, inner_radius=R_IN).iloc[0]
    assert out["rho_b"] == pytest.approx(1500.0, rel=1e-12)
    assert out["area"] == pytest.approx(RING_AREA, rel=1e-12)
    normal = lid_force + 1500.0 * G * RING_AREA * (lid_z - Z_SHEAR) + upper_z
    assert out["sigma"] == pytest.approx(normal / RING_AREA, rel=1e-12)
    # Uniform tau over the annulus: T = tau * 2 pi (R^3 - R_i^3) / 3.
    tau = 3.0 * torque / (2.0 * np.pi * (R**3 - R_IN**3))
    assert out["tau"] == pytest.approx(tau, rel=1e-12)
    assert out["mu"] == pytest.approx(tau * RING_AREA / normal, rel=1e-12)


def test_ring_bulk_values_recovered_per_cycle() -> None:
    values = shear_cell_bulk_values(
        ring_table(synthetic_run(CYCLES, seed=4)), R, Z_FLOOR, Z_SHEAR, G, inner_radius=R_IN
    )
    for spec, row in zip(CYCLES, values.itertuples(), strict=True):
        assert row.mu_psh == pytest.approx(spec["mu_psh"], abs=0.01)
        assert row.mu_sh == pytest.approx(spec["mu_sh"], abs=0.01)
        assert row.rho_b == pytest.approx(spec["rho_b"], rel=1e-3)
        # The target force is a stress on the annulus, not on the full disc.
        assert row.normal_stress == pytest.approx(spec["normal_stress"] * AREA / RING_AREA)


def test_ring_readout_needs_the_torque_and_a_valid_inner_radius() -> None:
    table = ring_table(synthetic_run(CYCLES[:1]))
    with pytest.raises(MissingColumnError, match="torque"):
        shear_stress_series(
            table.drop(columns=["torque"]), R, Z_FLOOR, Z_SHEAR, G, inner_radius=R_IN
        )
    with pytest.raises(ValueError, match="inner_radius"):
        shear_stress_series(table, R, Z_FLOOR, Z_SHEAR, G, inner_radius=R)
    # The split cell's columns are not what a ring table holds.
    with pytest.raises(MissingColumnError, match="shear_force"):
        shear_stress_series(table, R, Z_FLOOR, Z_SHEAR, G)


def test_ring_interior_density_replaces_the_cells_over_the_same_plateau() -> None:
    table = ring_table(synthetic_run(CYCLES, seed=4))
    volume = 2.0e-5  # m^3
    # The interior packs 12 % denser than the cell and its mass scatters by 1 % row to row.
    scatter = 1.0 + 0.01 * np.random.default_rng(3).standard_normal(len(table))
    cell_rho = table["mass"] / (RING_AREA * (table["lid_z"] - Z_FLOOR))
    table[INTERIOR_MASS_COLUMN] = 1.12 * cell_rho * volume * scatter
    plain = shear_cell_bulk_values(table, R, Z_FLOOR, Z_SHEAR, G, inner_radius=R_IN)
    values = shear_cell_bulk_values(
        table, R, Z_FLOOR, Z_SHEAR, G, inner_radius=R_IN, interior_volume=volume
    )
    for spec, row, base in zip(CYCLES, values.itertuples(), plain.itertuples(), strict=True):
        assert row.rho_b == pytest.approx(1.12 * spec["rho_b"], rel=3e-3)
        assert row.rho_b_cell == pytest.approx(spec["rho_b"], rel=1e-3)
        assert base.rho_b == base.rho_b_cell == row.rho_b_cell
        # The friction values do not depend on where the density is measured.
        assert (row.mu_psh, row.mu_sh) == (base.mu_psh, base.mu_sh)


def test_ring_interior_readout_rejects_a_missing_or_bad_mass_column() -> None:
    table = ring_table(synthetic_run(CYCLES[:1]))
    with pytest.raises(MissingColumnError, match=INTERIOR_MASS_COLUMN):
        shear_cell_bulk_values(
            table, R, Z_FLOOR, Z_SHEAR, G, inner_radius=R_IN, interior_volume=1e-5
        )
    table[INTERIOR_MASS_COLUMN] = 0.01
    table.loc[7, INTERIOR_MASS_COLUMN] = -1.0
    with pytest.raises(ValueError, match=rf"{INTERIOR_MASS_COLUMN}.*row 7"):
        shear_cell_bulk_values(
            table, R, Z_FLOOR, Z_SHEAR, G, inner_radius=R_IN, interior_volume=1e-5
        )
    with pytest.raises(ValueError, match="interior_volume"):
        shear_cell_bulk_values(
            table, R, Z_FLOOR, Z_SHEAR, G, inner_radius=R_IN, interior_volume=0.0
        )
