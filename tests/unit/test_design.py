"""Tests of demcal.design.build and demcal.design.table: factorial and sampled designs, load
conditions, table files."""

from __future__ import annotations

import itertools
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from demcal.core.config import load_config
from demcal.design.build import (
    build_design,
    factorial_design,
    latin_hypercube_design,
    random_design,
    sobol_design,
)
from demcal.design.cases import case_ids as study_case_ids
from demcal.design.cases import case_row, design_from_config, design_id, replicate_of
from demcal.design.table import (
    DesignSpecError,
    DesignTableError,
    case_ids,
    expand_load_conditions,
    read_design_table,
    write_design_table,
)

ROOT = Path(__file__).resolve().parents[2]
# The levels of the paper's Table 2, as the paper profile gives them to the workflow.
PAPER_TABLE2_LEVELS = load_config(ROOT / "config" / "paper.yaml")["design"]["levels"]

RANGES = {
    "coefficientFriction": (0.1, 1.0),
    "coefficientRollingFriction": (0.1, 1.0),
    "coefficientRestitution": (0.5, 0.9),
    "density": (2500.0, 3500.0),
}
STRESSES = (1068.0, 2029.0, 10070.0)
P_VALUES = (0.4, 0.6, 0.8, 1.0)


def test_case_ids_are_padded_and_sortable() -> None:
    assert case_ids(3) == ["c0001", "c0002", "c0003"]
    ids = case_ids(10000)
    assert ids[0] == "c00001" and ids[-1] == "c10000"
    assert sorted(ids) == ids


def test_paper_table2_factorial_is_complete() -> None:
    df = factorial_design(PAPER_TABLE2_LEVELS)
    assert len(df) == 3 * 3 * 3 * 3 * 4 == 324
    assert list(df.columns) == [
        "case_id",
        "coefficientFriction",
        "coefficientRollingFriction",
        "coefficientRestitution",
        "density",
        "dCylDp",
    ]
    assert df["case_id"].iloc[0] == "c0001" and df["case_id"].iloc[-1] == "c0324"
    params = df.drop(columns="case_id")
    # every combination exactly once
    combos = set(map(tuple, params.to_numpy()))
    assert combos == set(itertools.product(*PAPER_TABLE2_LEVELS.values()))
    assert len(combos) == 324
    # balanced: each level of a 3-level factor occurs 108 times, of dCylDp 81 times
    assert (df["coefficientFriction"].value_counts() == 108).all()
    assert (df["dCylDp"].value_counts() == 81).all()
    # the first column varies slowest, the last fastest
    assert df["dCylDp"].iloc[:4].tolist() == [20.0, 36.0, 38.0, 40.0]
    assert (df["coefficientFriction"].iloc[:108] == 0.4).all()


def test_factorial_column_order_does_not_depend_on_key_order() -> None:
    reordered = dict(reversed(list(PAPER_TABLE2_LEVELS.items())))
    pd.testing.assert_frame_equal(
        factorial_design(reordered), factorial_design(PAPER_TABLE2_LEVELS)
    )


@pytest.mark.parametrize(
    ("levels", "fragment"),
    [
        ({}, "levels"),
        ({"density": []}, "levels.density"),
        ({"density": [2500.0, 2500.0]}, "levels.density"),
        ({"density": [2500.0, "heavy"]}, "levels.density"),
        ({"density": [2500.0, float("nan")]}, "levels.density"),
    ],
)
def test_factorial_bad_levels(levels: dict, fragment: str) -> None:
    with pytest.raises(DesignSpecError, match=fragment):
        factorial_design(levels)


@pytest.mark.parametrize("design", [random_design, latin_hypercube_design, sobol_design])
def test_sampled_designs_are_reproducible_and_in_range(design) -> None:
    a = design(RANGES, 32, seed=11)
    b = design(RANGES, 32, seed=11)
    c = design(RANGES, 32, seed=12)
    pd.testing.assert_frame_equal(a, b)
    assert not np.allclose(a["coefficientFriction"], c["coefficientFriction"])
    assert len(a) == 32 and a["case_id"].tolist() == case_ids(32)
    for name, (low, high) in RANGES.items():
        assert a[name].between(low, high).all()
        # 32 points spread over the range, not clustered
        assert a[name].max() - a[name].min() > 0.7 * (high - low)


def test_lhs_has_one_point_per_stratum() -> None:
    n = 50
    df = latin_hypercube_design(RANGES, n, seed=3)
    for name, (low, high) in RANGES.items():
        strata = np.floor((df[name] - low) / (high - low) * n).astype(int)
        assert sorted(strata) == list(range(n))


def test_sobol_power_of_two_is_balanced_and_silent() -> None:
    n = 64
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        df = sobol_design(RANGES, n, seed=5)
    for name, (low, high) in RANGES.items():
        strata = np.floor((df[name] - low) / (high - low) * n).astype(int)
        assert sorted(strata) == list(range(n))
    # 2-D projections are (0, m, 2)-nets as well: 8 x 8 cells hold one point each
    u = (df["coefficientFriction"] - 0.1) / 0.9
    v = (df["density"] - 2500.0) / 1000.0
    cells = set(zip(np.floor(u * 8).astype(int), np.floor(v * 8).astype(int), strict=True))
    assert len(cells) == 64


def test_sobol_warns_when_n_is_not_a_power_of_two() -> None:
    with pytest.warns(UserWarning, match="power of two"):
        df = sobol_design(RANGES, 24, seed=5)
    assert len(df) == 24


def test_choices_fixed_and_integer_columns() -> None:
    allowed = [20.0, 36.0, 38.0, 40.0]
    df = latin_hypercube_design(
        {"coefficientFriction": (0.1, 1.0), "nLayers": (2, 5)},
        40,
        seed=9,
        integer=["nLayers"],
        choices={"dCylDp": allowed},
        fixed={"youngsModulus": 1.0e7, "poissonsRatio": 0.4},
    )
    assert list(df.columns) == [
        "case_id",
        "coefficientFriction",
        "youngsModulus",
        "poissonsRatio",
        "dCylDp",
        "nLayers",
    ]
    # LHS stratifies the index: 40 cases over 4 choices -> 10 each
    assert df["dCylDp"].value_counts().to_dict() == dict.fromkeys(allowed, 10)
    # 40 cases over the 4 integers 2..5 -> 10 each, all whole numbers
    assert df["nLayers"].value_counts().to_dict() == {2.0: 10, 3.0: 10, 4.0: 10, 5.0: 10}
    assert (df["youngsModulus"] == 1.0e7).all() and (df["poissonsRatio"] == 0.4).all()


def test_random_integer_column_reaches_both_bounds() -> None:
    df = random_design({"k": (0, 3)}, 400, seed=1, integer=["k"])
    assert set(df["k"]) == {0.0, 1.0, 2.0, 3.0}


@pytest.mark.parametrize("kind", ["random", "lhs", "sobol"])
def test_build_design_same_spec_same_table(kind: str) -> None:
    spec = {
        "kind": kind,
        "n": 16,
        "seed": 2024,
        "ranges": {k: list(v) for k, v in RANGES.items()},
        "choices": {"dCylDp": [20, 36, 38, 40]},
        "fixed": {"youngsModulus": 1.0e7},
    }
    a = build_design(spec)
    b = build_design(dict(spec))
    pd.testing.assert_frame_equal(a, b)
    # the same content with keys in another order gives the same table
    shuffled = {
        "fixed": spec["fixed"],
        "ranges": dict(reversed(list(spec["ranges"].items()))),
        "choices": spec["choices"],
        "seed": 2024,
        "n": 16,
        "kind": kind,
    }
    pd.testing.assert_frame_equal(build_design(shuffled), a)
    direct = {"random": random_design, "lhs": latin_hypercube_design, "sobol": sobol_design}[kind](
        RANGES, 16, 2024, choices={"dCylDp": [20, 36, 38, 40]}, fixed={"youngsModulus": 1.0e7}
    )
    pd.testing.assert_frame_equal(direct, a)


def test_build_design_factorial_with_fixed() -> None:
    df = build_design(
        {"kind": "factorial", "levels": PAPER_TABLE2_LEVELS, "fixed": {"youngsModulus": 1e7}}
    )
    assert len(df) == 324
    assert list(df.columns).index("youngsModulus") == 5  # canonical: before dCylDp
    assert (df["youngsModulus"] == 1e7).all()


@pytest.mark.parametrize(
    ("spec", "fragment"),
    [
        ({}, "'kind'"),
        ({"kind": "grid"}, "'kind'"),
        ({"kind": "factorial"}, "'levels'"),
        ({"kind": "lhs", "seed": 1, "ranges": {"density": [1, 2]}}, "'n'"),
        ({"kind": "lhs", "n": 4, "ranges": {"density": [1, 2]}}, "'seed'"),
        ({"kind": "lhs", "n": 4, "seed": 1}, "'ranges'"),
        ({"kind": "lhs", "n": 4, "seed": 1, "ranges": {"density": [2, 1]}}, "ranges.density"),
        ({"kind": "lhs", "n": 4, "seed": 1, "ranges": {"density": [1]}}, "ranges.density"),
        ({"kind": "lhs", "n": 0, "seed": 1, "ranges": {"density": [1, 2]}}, "n:"),
        ({"kind": "lhs", "n": 4, "seed": 1, "ranges": {"a": [1, 2]}, "nn": 3}, "'nn'"),
        (
            {"kind": "lhs", "n": 4, "seed": 1, "ranges": {"a": [1, 2]}, "fixed": {"a": 1.5}},
            "fixed.a",
        ),
        (
            {"kind": "lhs", "n": 4, "seed": 1, "ranges": {"a": [1, 2]}, "integer": ["b"]},
            "integer",
        ),
        (
            {"kind": "lhs", "n": 4, "seed": 1, "ranges": {"a": [1, 2.5]}, "integer": ["a"]},
            "ranges.a",
        ),
        ({"kind": "lhs", "n": 4, "seed": 1, "choices": {"dCylDp": []}}, "choices.dCylDp"),
    ],
)
def test_build_design_errors_name_the_key(spec: dict, fragment: str) -> None:
    with pytest.raises(DesignSpecError, match=fragment):
        build_design(spec)


def test_expand_load_conditions_twelve_per_case() -> None:
    design = factorial_design(PAPER_TABLE2_LEVELS)
    expanded = expand_load_conditions(design, STRESSES, P_VALUES)
    assert len(expanded) == 324 * 12
    assert list(expanded.columns) == [*design.columns, "normal_stress", "P"]
    assert (expanded.groupby("case_id").size() == 12).all()
    first = expanded[expanded["case_id"] == "c0001"]
    assert list(zip(first["normal_stress"], first["P"], strict=True)) == list(
        itertools.product(STRESSES, P_VALUES)
    )
    # parameters are carried over unchanged
    merged = expanded.drop(columns=["normal_stress", "P"]).drop_duplicates("case_id")
    pd.testing.assert_frame_equal(merged.reset_index(drop=True), design)


@pytest.mark.parametrize(
    ("stresses", "loads"), [((), (1.0,)), ((-5.0,), (1.0,)), ((1068.0,), (1.2,))]
)
def test_expand_load_conditions_rejects_bad_values(stresses, loads) -> None:
    design = factorial_design({"density": [2500.0]})
    with pytest.raises(DesignSpecError):
        expand_load_conditions(design, stresses, loads)


def test_table_round_trip_is_exact_and_byte_stable(tmp_path: Path) -> None:
    design = sobol_design(RANGES, 16, seed=4, choices={"dCylDp": [20, 40]})
    expanded = expand_load_conditions(design, STRESSES, P_VALUES)
    for i, df in enumerate((design, expanded)):
        first = tmp_path / f"t{i}" / "a.csv"
        second = tmp_path / f"t{i}" / "b.csv"
        write_design_table(df, first)
        back = read_design_table(first)
        pd.testing.assert_frame_equal(back, df)
        write_design_table(back, second)
        assert first.read_bytes() == second.read_bytes()


def test_table_format_is_fixed(tmp_path: Path) -> None:
    df = pd.DataFrame(
        {"case_id": ["c0001", "c0002"], "density": [2500.0, 3000.5], "mu": [0.1, 1 / 3]}
    )
    path = tmp_path / "d.csv"
    write_design_table(df, path)
    assert path.read_bytes() == (
        b"case_id,density,mu\nc0001,2500,0.1\nc0002,3000.5,0.333333333333\n"
    )


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("id,density\nc0001,2500\n", "missing column 'case_id'"),
        ("case_id,density\nc0001,2500\nc0001,2600\n", "repeats id 'c0001'"),
        ("case_id,density\ncase1,2500\n", "malformed id 'case1'"),
        (
            "case_id,normal_stress,P\nc0001,1068,1\nc0001,1068,0.4\nc0001,1068,1\n",
            "repeats id 'c0001' with normal_stress=1068 and P=1",
        ),
        ("case_id,density\nc0001,2500\nc0002,heavy\n", "column 'density'.*'heavy'.*c0002"),
        ("case_id,density\nc0001,\n", "column 'density'"),
    ],
)
def test_read_design_table_errors_name_file_and_column(
    tmp_path: Path, text: str, fragment: str
) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(DesignTableError, match=fragment) as info:
        read_design_table(path)
    assert "bad.csv" in str(info.value)


def test_read_design_table_missing_file(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"nope\.csv"):
        read_design_table(tmp_path / "nope.csv")


def test_heap_only_sets_follow_the_shared_sets() -> None:
    root = Path(__file__).resolve().parents[2]
    quick = load_config(root / "config" / "config.yaml")
    # The study's own counts, with two heaps per set so that the heaps' order shows.
    quick["design"] = {**quick["design"], "repose_replicates": 2}
    n, extra = quick["design"]["n"], quick["design"]["repose_extra_sets"]
    assert (n, extra) == (16, 48)
    heaps_only = {**quick, "design": {**quick["design"], "shear_extra_sets": 0}}
    design = design_from_config(heaps_only)
    assert design["case_id"].tolist() == case_ids(n + extra)
    # The shared sets are the design without heap-only sets, unchanged.
    alone = design_from_config(
        {**heaps_only, "design": {**heaps_only["design"], "repose_extra_sets": 0}}
    )
    pd.testing.assert_frame_equal(design.iloc[:n], alone)
    # The heap-only sets are a Latin hypercube of their own (seed + 1) over the same box.
    heaps = design.iloc[n:]
    for name, (low, high) in quick["design"]["ranges"].items():
        column = heaps[name].to_numpy()
        assert low <= column.min() and column.max() <= high
        strata = np.floor((column - low) / (high - low) * extra).astype(int)
        assert sorted(strata.tolist()) == list(range(extra)), name
    heap_runs = study_case_ids(heaps_only, design, "angle_of_repose")
    assert heap_runs[::2] == case_ids(n + extra)  # each followed by its second heap
    every = {**heaps_only, "design": {**heaps_only["design"], "shared_stresses": "all"}}
    shear = study_case_ids(every, design, "shear_cell")
    assert shear == [f"{c}_s{k}" for c in case_ids(n) for k in (1, 2, 3)]
    # A factorial design and a sequential study's rounds choose every set for both tests: the
    # key is ignored there (a profile merged over the quick one inherits it).
    paper = load_config(root / "config" / "paper.yaml")
    paper["design"]["repose_extra_sets"] = 48
    assert len(design_from_config(paper)) == 3 * 3 * 3 * 3 * 4
    sequential = {**quick, "sequential": {**quick["sequential"], "enabled": True}}
    assert len(design_from_config(sequential)) == n


def test_shear_only_sets_run_one_stress_each_after_the_heap_only_sets() -> None:
    root = Path(__file__).resolve().parents[2]
    quick = load_config(root / "config" / "config.yaml")
    n, heaps = quick["design"]["n"], quick["design"]["repose_extra_sets"]
    # The quick study: 16 shared sets at one stress each, then 32 shear-only sets.
    assert (quick["design"]["shared_stresses"], quick["design"]["shear_extra_sets"]) == ("one", 32)
    design = design_from_config(quick)
    assert design["case_id"].tolist() == case_ids(n + heaps + 32)
    without = {**quick, "design": {**quick["design"], "shear_extra_sets": 0}}
    # The shared and heap-only sets are those of the study without shear-only sets.
    pd.testing.assert_frame_equal(design.iloc[: n + heaps], design_from_config(without))
    # A Latin hypercube of their own (seed + 2), not a copy of the heap-only one.
    extra = design.iloc[n + heaps :]
    mu_s = extra["coefficientFriction"].to_numpy()
    strata = np.floor((mu_s - 0.1) / 0.9 * 32).astype(int)
    assert sorted(strata.tolist()) == list(range(32))
    assert not np.isin(mu_s, design["coefficientFriction"].iloc[: n + heaps]).any()
    # Heaps: the shared and heap-only sets; none on a shear-only set.
    heap_runs = study_case_ids(quick, design, "angle_of_repose")
    assert heap_runs == study_case_ids(without, design_from_config(without), "angle_of_repose")
    # Shear cell: one stress per set in turn, shared sets first: 48 decks as for 16 x 3.
    shear = study_case_ids(quick, design, "shear_cell")
    ids = case_ids(n + heaps + 32)
    rotate = [f"{c}_s{j % 3 + 1}" for j, c in enumerate(ids[:n])]
    assert shear == rotate + [f"{c}_s{j % 3 + 1}" for j, c in enumerate(ids[n + heaps :])]
    assert len(shear) == 48
    row = case_row(quick, design, "shear_cell", shear[-1])  # the 32nd shear-only set, at s2
    assert row["normal_stress"] == quick["shear_cell"]["normal_stresses"][1]
    # Every stress for the shared sets; shear-only sets stay at one.
    every = {**quick, "design": {**quick["design"], "shared_stresses": "all"}}
    runs = study_case_ids(every, design, "shear_cell")
    assert runs == runs_all(ids[:n]) + shear[n:]
    # With one deck per P, a set runs every P of its stress; replicates follow.
    split = {
        **quick,
        "design": {**quick["design"], "replicates": 2, "repose_replicates": 1},
        "shear_cell": {**quick["shear_cell"], "separate_runs": True},
    }
    runs = study_case_ids(split, design, "shear_cell")
    first = ids[n + heaps]
    assert [r for r in runs if r.startswith(first)] == [
        f"{first}{r}_s1_p{j}" for j in (1, 2, 3, 4) for r in ("", "_r2")
    ]
    # Ignored where every set runs both tests.
    sequential = {**quick, "sequential": {**quick["sequential"], "enabled": True}}
    assert len(design_from_config(sequential)) == n
    assert study_case_ids(sequential, design.iloc[:n], "shear_cell") == runs_all(ids[:n])


def runs_all(ids: list[str]) -> list[str]:
    """Shear-cell decks of ``ids`` at all three quick stresses."""
    return [f"{c}_s{k}" for c in ids for k in (1, 2, 3)]


def test_replicates_follow_every_case_from_their_own_packing() -> None:
    root = Path(__file__).resolve().parents[2]
    quick = load_config(root / "config" / "config.yaml")
    # One run of every shear deck (the quick study's), two heaps of every set.
    assert quick["design"]["replicates"] == 1
    quick["design"] = {**quick["design"], "repose_replicates": 2}
    design = design_from_config(quick)
    # the sets that run the heap (the 32 shear-only sets do not)
    sets = quick["design"]["n"] + quick["design"]["repose_extra_sets"]
    one = {t: study_case_ids(quick, design, t) for t in ("angle_of_repose", "shear_cell")}
    assert one["angle_of_repose"][:3] == ["c0001", "c0001_r2", "c0002"]
    assert len(one["angle_of_repose"]) == 2 * sets
    assert not [c for c in one["shear_cell"] if "_r" in c]
    # Without repose_replicates the heaps follow design.replicates.
    shared = {k: v for k, v in quick["design"].items() if k != "repose_replicates"}
    three = {**quick, "design": {**shared, "replicates": 3}}
    pd.testing.assert_frame_equal(design_from_config(three), design)
    heaps = study_case_ids(three, design, "angle_of_repose")
    assert heaps[:4] == ["c0001", "c0001_r2", "c0001_r3", "c0002"]
    assert len(heaps) == 3 * sets
    shear = study_case_ids(three, design, "shear_cell")
    assert shear[:4] == ["c0001_s1", "c0001_r2_s1", "c0001_r3_s1", "c0002_s2"]
    assert [c for c in shear if "_r" not in c] == one["shear_cell"]
    # ... and with it the heaps alone.
    heaps_only = {**quick, "design": {**shared, "replicates": 3, "repose_replicates": 1}}
    assert study_case_ids(heaps_only, design, "angle_of_repose") == list(design["case_id"])[:sets]
    assert study_case_ids(heaps_only, design, "shear_cell") == shear
    assert replicate_of("c0012_r3_s2") == ("c0012_s2", 3)
    assert replicate_of("c0012_s2") == ("c0012_s2", 1)
    assert replicate_of("identified2_s1_p1") == ("identified2_s1_p1", 1)
    assert design_id("c0012_r3_s2") == design_id("c0012_r3") == design_id("c0012") == "c0012"
    # A replicate is its design row at the same load, with seed + (k - 1) x 1000.
    first = case_row(three, design, "shear_cell", "c0005_s2")
    third = case_row(three, design, "shear_cell", "c0005_r3_s2")
    assert "seed" not in first
    assert third.pop("seed") == quick["seed"] + 2000
    assert {**third, "case_id": "c0005_s2"} == first
    assert case_row(three, design, "angle_of_repose", "c0005_r2")["seed"] == quick["seed"] + 1000
