"""Stresses across the shear plane from a contact list (synthetic contacts, known sums)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from demcal.virtual_tests.shear_cell.plane_stress import CONTACT_COLUMNS, plane_stress
from demcal.virtual_tests.shear_cell.readout import overlap_area

R, Z = 0.02, 0.015


def contacts(rows: list[tuple[float, ...]]) -> pd.DataFrame:
    return pd.DataFrame(rows, columns=list(CONTACT_COLUMNS))


def test_only_contacts_across_the_plane_inside_the_overlap_count() -> None:
    d = 0.002
    table = contacts(
        [
            # across the plane, particle 1 above: force on the upper one counts as it is
            (0.0, 0.0, Z + d / 2, 0.0, 0.0, Z - d / 2, 1, 2, 0, -0.3, 0.0, 1.0),
            # across the plane, particle 1 below: the force on the upper one is -f
            (0.005, 0.0, Z - d / 2, 0.005, 0.0, Z + d / 2, 3, 4, 0, 0.1, 0.0, -1.0),
            # both above the plane: not counted
            (0.0, 0.005, Z + d, 0.0, 0.005, Z + 2 * d, 5, 6, 0, 5.0, 0.0, 5.0),
            # across the plane but outside the lower circle, which moved 8 mm in -x
            (0.015, 0.0, Z + d / 2, 0.015, 0.0, Z - d / 2, 7, 8, 0, -9.0, 0.0, 9.0),
        ]
    )
    got = plane_stress(table, Z, R, travel=-0.008, margin=0.0)
    area = overlap_area(R, 0.008)
    assert got["n"] == 2
    assert got["area"] == pytest.approx(area)
    assert got["tau"] == pytest.approx(0.4 / area)
    assert got["sigma"] == pytest.approx(2.0 / area)
    assert got["mu"] == pytest.approx(0.2)
    # A margin of 7.5 mm from both walls leaves only the central contact.
    central = plane_stress(table, Z, R, travel=-0.008, margin=0.0075)
    assert central["n"] == 1 and central["mu"] == pytest.approx(0.3)


def test_an_empty_plane_and_a_bad_margin() -> None:
    table = contacts([(0.0, 0.0, Z + 0.002, 0.0, 0.0, Z + 0.004, 1, 2, 0, 1.0, 0.0, 1.0)])
    got = plane_stress(table, Z, R, travel=0.0, margin=0.0)
    assert got["n"] == 0 and np.isnan(got["mu"])
    with pytest.raises(ValueError, match="margin"):
        plane_stress(table, Z, R, travel=0.0, margin=R)
