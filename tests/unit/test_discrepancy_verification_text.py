"""The Show step's verification report says what the DEM runs showed, in its first line."""

import pandas as pd
import pytest

from demcal.discrepancy.effect_verdict import CONFIRMED, GAP_REMAINS, NOT_CONFIRMED
from demcal.discrepancy.report import verification_markdown


def table() -> pd.DataFrame:
    """Nine fitted values; DEM means 10 % low before and 3 % low after, sigma 5 %."""
    rows = []
    for stress in (1068.0, 2029.0, 4000.0):
        for observable, measured in (("mu_psh", 0.60), ("mu_sh", 0.55), ("rho_b", 1580.0)):
            row = {
                "observable": observable,
                "normal_stress": stress,
                "P": 0.5,
                "held_out": False,
                "measured": measured,
                "sigma": 0.05 * measured,
            }
            for label, ratio in (("before", 0.90), ("after", 0.97)):
                row[f"dem_{label}"] = ratio * measured
                row[f"dem_{label}_sd"] = 0.01 * measured
                row[f"dem_{label}_runs"] = 3
                row[f"z_dem_{label}"] = (ratio - 1.0) / 0.05
            rows.append(row)
    return pd.DataFrame(rows)


SUMMARY = {
    "extended": True,
    "winner": "cohesion",
    "parameter": "cohesionEnergyDensity",
    "identified": {"coefficientFriction": 0.1, "cohesionEnergyDensity": 4.8e4},
    "replicates": 3,
    "dem_gap_before": 2.0,
    "dem_gap_after": 0.6,
    "held_out": [],
    "gap_before_common": 1.98,
    "gap_after": 1.62,
    "gap_ratio": 1.22,
    "alpha": 0.05,
    "dem_values": 9,
    "dem_gap_bound": 1.371,
}


@pytest.mark.parametrize(
    ("verdict", "first"),
    [
        (CONFIRMED, "**The DEM runs confirm cohesion**"),
        (GAP_REMAINS, "**The DEM runs show cohesion closing part of the gap, not all of it**"),
        (NOT_CONFIRMED, "**The DEM runs do not confirm cohesion**"),
    ],
)
def test_the_first_line_states_the_dem_verdict(verdict, first):
    summary = {**SUMMARY, "dem_verdict": verdict}
    if verdict == GAP_REMAINS:
        summary["dem_gap_after"] = 1.81
    text = verification_markdown(table(), summary)
    lines = [line for line in text.splitlines() if line.strip()]
    assert lines[1].startswith(first), lines[1]
    if verdict == GAP_REMAINS:
        # The figures behind the verdict: the gap left and the largest gap noise explains.
        assert (
            "the DEM gap left, 1.810, is more than noise explains (at most 1.371 over 9"
            in (lines[1])
        )
        assert "something is still missing" in lines[1]
