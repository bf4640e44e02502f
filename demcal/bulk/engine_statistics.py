"""Statistics of a bulk-level engine comparison: Welch's t-test with a Bonferroni correction.

For every parameter set and bulk value (``mu_psh``, ``mu_sh``, ``rho_b``, ``aor``) the seed
samples of the two engines are compared by Welch's two-sample t-test (unequal variances,
two-sided). With ``m`` such comparisons the Bonferroni correction tests each one at
``alpha / m``, which bounds the family-wise false-alarm rate (the probability that at least one
comparison is flagged although the engines agree in every mean) by ``alpha``. A comparison
*passes* when its p-value is at least ``alpha / m``.

The same machinery compares two parameter sets on one engine (:func:`compare_groups`), which
shows that a real difference (e.g. sliding friction 0.3 against 0.9) is detected.

Beside each mean test the Brown-Forsythe test (Levene's test about the medians) asks whether the
two samples scatter alike (``p_spread``). It is reported, not part of pass or fail: the engines
must agree in the mean, and a handful of seeds per engine gives a spread test little power,
but one engine scattering more from seed to seed would cost every study replicate runs.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats

from demcal.bulk.engine_comparison import BULK_VALUES

__all__ = [
    "Comparison",
    "compare_engines",
    "compare_groups",
    "markdown_table",
    "spread_test",
    "welch_test",
]


def _finite_samples(a: Sequence[float], b: Sequence[float]) -> tuple[np.ndarray, np.ndarray] | None:
    """``a`` and ``b`` without NaN entries; None when either keeps fewer than two values."""
    x = np.asarray(a, dtype=float)
    y = np.asarray(b, dtype=float)
    x, y = x[np.isfinite(x)], y[np.isfinite(y)]
    return (x, y) if len(x) >= 2 and len(y) >= 2 else None


def welch_test(a: Sequence[float], b: Sequence[float]) -> float:
    """Two-sided p-value of Welch's t-test of equal means of ``a`` and ``b``.

    NaN entries are dropped. Two samples without scatter give 1 for equal and 0 for different
    means; fewer than two values in a sample give NaN.
    """
    samples = _finite_samples(a, b)
    if samples is None:
        return math.nan
    x, y = samples
    if np.ptp(x) == 0.0 and np.ptp(y) == 0.0:
        return 1.0 if x[0] == y[0] else 0.0
    return float(stats.ttest_ind(x, y, equal_var=False).pvalue)


def spread_test(a: Sequence[float], b: Sequence[float]) -> float:
    """Two-sided p-value of the Brown-Forsythe test of equal spread of ``a`` and ``b``.

    Levene's test on the absolute deviations from each sample's median. NaN entries are
    dropped. Two samples without scatter give 1; fewer than two values in a sample give NaN.
    """
    samples = _finite_samples(a, b)
    if samples is None:
        return math.nan
    x, y = samples
    if np.ptp(x) == 0.0 and np.ptp(y) == 0.0:
        return 1.0
    return float(stats.levene(x, y, center="median").pvalue)


@dataclass
class Comparison:
    """Result of a family of Welch tests with a Bonferroni correction.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per comparison: ``set``, ``quantity``, ``n_a``, ``mean_a``, ``sd_a``, ``n_b``,
        ``mean_b``, ``sd_b``, ``difference`` (mean_b - mean_a), ``p_value``, ``passed`` and
        ``p_spread`` (Brown-Forsythe, not part of ``passed``).
    alpha : float
        Family-wise significance level.
    per_test_alpha : float
        ``alpha`` divided by the number of comparisons (Bonferroni).
    labels : tuple of str
        Names of group a and group b (e.g. ``("liggghts", "engine")``).
    """

    table: pd.DataFrame
    alpha: float
    per_test_alpha: float
    labels: tuple[str, str]

    @property
    def all_passed(self) -> bool:
        """Whether no comparison is significant at the family-wise level."""
        return bool(self.table["passed"].all())

    @property
    def flagged(self) -> pd.DataFrame:
        """The comparisons with a significant difference."""
        return self.table[~self.table["passed"]]


def compare_groups(
    pairs: Mapping[tuple[str, str], tuple[Sequence[float], Sequence[float]]],
    alpha: float = 0.01,
    labels: tuple[str, str] = ("a", "b"),
) -> Comparison:
    """Welch's t-test per pair of samples, Bonferroni-corrected over all pairs.

    Parameters
    ----------
    pairs : mapping
        (set name, bulk value) -> (samples of group a, samples of group b).
    alpha : float
        Family-wise false-alarm rate; each test is made at ``alpha / len(pairs)``.
    labels : tuple of str
        Names of the groups, kept for the table.

    Returns
    -------
    Comparison
        The table and levels. A comparison whose p-value is NaN (too few samples) fails.
    """
    if not pairs:
        raise ValueError("nothing to compare")
    per_test = alpha / len(pairs)
    rows = []
    for (set_name, quantity), (a, b) in pairs.items():
        x = np.asarray(a, dtype=float)
        y = np.asarray(b, dtype=float)
        x, y = x[np.isfinite(x)], y[np.isfinite(y)]
        p = welch_test(x, y)
        rows.append(
            {
                "set": set_name,
                "quantity": quantity,
                "n_a": len(x),
                "mean_a": float(np.mean(x)) if len(x) else math.nan,
                "sd_a": float(np.std(x, ddof=1)) if len(x) > 1 else math.nan,
                "n_b": len(y),
                "mean_b": float(np.mean(y)) if len(y) else math.nan,
                "sd_b": float(np.std(y, ddof=1)) if len(y) > 1 else math.nan,
                "difference": (float(np.mean(y) - np.mean(x)) if len(x) and len(y) else math.nan),
                "p_value": p,
                "passed": bool(np.isfinite(p) and p >= per_test),
                "p_spread": spread_test(x, y),
            }
        )
    return Comparison(pd.DataFrame(rows), float(alpha), per_test, labels)


def compare_engines(
    values: pd.DataFrame,
    reference: str = "liggghts",
    other: str = "engine",
    alpha: float = 0.01,
    quantities: Iterable[str] | None = None,
) -> Comparison:
    """Compare the engines' seed means of every set and bulk value in ``values``.

    Parameters
    ----------
    values : pandas.DataFrame
        From :func:`collect_values`.
    reference, other : str
        Engine names; the difference is ``other - reference``.
    alpha : float
        Family-wise false-alarm rate (Bonferroni over all sets and bulk values present).
    quantities : iterable of str, optional
        Bulk values to compare; default all in ``values`` (in the order of
        :data:`BULK_VALUES`).

    Returns
    -------
    Comparison
    """
    present = set(values["quantity"])
    wanted = [q for q in (quantities or BULK_VALUES) if q in present]
    pairs = {}
    for set_name in dict.fromkeys(values["set"]):
        for quantity in wanted:
            sel = values[(values["set"] == set_name) & (values["quantity"] == quantity)]
            a = sel.loc[sel["engine"] == reference, "value"].to_numpy()
            b = sel.loc[sel["engine"] == other, "value"].to_numpy()
            if len(a) or len(b):
                pairs[(set_name, quantity)] = (a, b)
    return compare_groups(pairs, alpha=alpha, labels=(reference, other))


def _fmt(value: float, quantity: str) -> str:
    if not np.isfinite(value):
        return "-"
    if quantity == "rho_b":
        return f"{value:.0f}"
    if quantity == "aor":
        return f"{value:.2f}"
    return f"{value:.3f}"


def markdown_table(comparison: Comparison) -> str:
    """The comparison as a Markdown table, with the test and its levels in a line above.

    Columns: set, bulk value, n, mean and seed sd of each group, difference (b - a), p-value
    and pass/fail, and the p-value of equal spread. Units: rho_b in kg/m^3, aor in degrees,
    mu_psh and mu_sh dimensionless.
    """
    a, b = comparison.labels
    m = len(comparison.table)
    head = (
        f"Welch's two-sample t-test per set and bulk value, Bonferroni over {m} comparisons: "
        f"family-wise alpha = {comparison.alpha:g}, per test p < {comparison.per_test_alpha:.2g} "
        "is a significant difference (fail). Beside it the Brown-Forsythe test of equal seed "
        "scatter (p spread), reported only.\n\n"
    )
    lines = [
        f"| set | value | n {a} / {b} | mean {a} | sd {a} | mean {b} | sd {b} | "
        f"difference {b} - {a} | p | result | p spread |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in comparison.table.itertuples():
        q = str(r.quantity)
        p = "-" if not np.isfinite(r.p_value) else f"{r.p_value:.2g}"
        spread = "-" if not np.isfinite(r.p_spread) else f"{r.p_spread:.2g}"
        lines.append(
            f"| {r.set} | {q} | {r.n_a} / {r.n_b} | {_fmt(r.mean_a, q)} | {_fmt(r.sd_a, q)} | "
            f"{_fmt(r.mean_b, q)} | {_fmt(r.sd_b, q)} | {_fmt(r.difference, q)} | {p} | "
            f"{'pass' if r.passed else 'FAIL'} | {spread} |"
        )
    return head + "\n".join(lines) + "\n"
