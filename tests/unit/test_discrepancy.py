"""Find step of the discrepancy workflow on analytic surrogates with a known truth."""

import math

import numpy as np
import pandas as pd
import pytest

from demcal.core.experiments import Experiment, MeasuredCondition
from demcal.discrepancy.best_fit import (
    ParameterBox,
    exceedance_p,
    minimise_chi2,
    pinned_parameters,
)
from demcal.discrepancy.find import describe_disagreement, find
from demcal.discrepancy.observations import SurrogateModel, format_stress, observation_table

FEATURES = ["coefficientFriction", "density", "normal_stress", "P"]
STRESSES = (1068.0, 2029.0, 10070.0)


class Analytic:
    """A surrogate given by a formula of its input matrix."""

    def __init__(self, formula):
        self.formula = formula
        self.calls = 0

    def predict(self, X):
        self.calls += 1
        return self.formula(np.asarray(X, dtype=float))


def mu_psh(X):
    return 0.2 + 0.6 * X[:, 0]


def rho_b(X):
    return X[:, 1] * (0.62 - 0.08 * X[:, 0])


SURROGATES = {"mu_psh": (Analytic(mu_psh), FEATURES), "rho_b": (Analytic(rho_b), FEATURES)}
BOX = ParameterBox({"coefficientFriction": (0.1, 1.0), "density": (2500.0, 3500.0)})


def experiment(mu: float, density: float, extra=lambda name, stress: 0.0) -> Experiment:
    """Measurements of the analytic material, plus ``extra(observable, stress)``."""
    conds = []
    for stress in STRESSES:
        for p in (0.5, 1.0):
            values = {
                "mu_psh": 0.2 + 0.6 * mu + extra("mu_psh", stress),
                "rho_b": density * (0.62 - 0.08 * mu) + extra("rho_b", stress),
            }
            conds.append(MeasuredCondition(values, {"mu_psh": 0.01, "rho_b": 8.0}, stress, p))
    return Experiment("analytic", "test", conds)


def model_for(exp: Experiment) -> SurrogateModel:
    obs = observation_table(exp, {"mu_psh": 0.005, "rho_b": 4.0}, 0.05)
    return SurrogateModel(SURROGATES, obs, BOX.names)


def test_observation_table_combines_uncertainties():
    conds = [MeasuredCondition({"mu_psh": 0.6, "rho_b": 1700.0}, {"rho_b": 30.0}, 1068.0, 1.0)]
    exp = Experiment("m", "", conds, angle_of_repose=38.0, angle_of_repose_sd=1.5)
    obs = observation_table(exp, {"mu_psh": 0.04, "rho_b": 40.0, "aor": 2.0}, 0.05)
    assert list(obs["observable"]) == ["mu_psh", "rho_b", "aor"]
    # No sd for mu_psh: tolerance * value = 0.03, combined with the RMSE 0.04 -> 0.05.
    assert obs["sigma"].iloc[0] == pytest.approx(0.05)
    assert obs["sigma"].iloc[1] == pytest.approx(50.0)
    assert obs["sigma"].iloc[2] == pytest.approx(2.5)
    assert math.isnan(obs["normal_stress"].iloc[2])


def test_observation_table_needs_a_surrogate_per_measured_value():
    conds = [MeasuredCondition({"mu_sh": 0.6}, {}, 1068.0, 1.0)]
    with pytest.raises(KeyError, match="mu_sh"):
        observation_table(Experiment("m", "", conds), {"mu_psh": 0.04}, 0.05, ["mu_sh"])


def test_parameter_box_grid_and_integer_axes():
    box = ParameterBox({"a": (0.0, 1.0), "n": (1.0, 3.0)}, frozenset({"n"}))
    axes = box.axes(5)
    assert list(axes["n"]) == [1.0, 2.0, 3.0]
    grid = box.grid(5)
    assert grid.shape == (15, 2)
    assert set(map(tuple, grid)) == {(a, n) for a in axes["a"] for n in axes["n"]}
    with pytest.raises(ValueError, match="low <= high"):
        ParameterBox({"a": (1.0, 0.0)})


def test_surrogate_model_names_an_unknown_input():
    exp = experiment(0.4, 3000.0)
    obs = observation_table(exp, {"mu_psh": 0.005, "rho_b": 4.0}, 0.05)
    with pytest.raises(KeyError, match="density"):
        SurrogateModel(SURROGATES, obs, ["coefficientFriction"])


def test_minimise_chi2_refines_a_quadratic_to_its_minimum():
    box = ParameterBox({"x": (0.0, 1.0), "y": (-2.0, 2.0)})
    grid = box.grid(6)

    def objective(theta):
        return (theta[:, 0] - 0.3141) ** 2 + 4.0 * (theta[:, 1] - 0.777) ** 2 + 1.5

    theta, value = minimise_chi2(objective, box, grid, objective(grid))
    assert theta == pytest.approx([0.3141, 0.777], abs=1e-4)
    assert value == pytest.approx(1.5, abs=1e-7)


def test_find_recovers_the_truth_and_says_nothing_is_missing():
    result = find(model_for(experiment(0.37, 2890.0)), BOX, 31)
    assert result.best.theta["coefficientFriction"] == pytest.approx(0.37, abs=1e-3)
    assert result.best.theta["density"] == pytest.approx(2890.0, abs=2.0)
    assert result.gap < 0.05
    assert not result.missing and "nothing missing" in result.verdict
    assert all(" fits at " in s for s in result.sentences)


def test_find_inside_the_box_pins_nothing():
    result = find(model_for(experiment(0.37, 2890.0)), BOX, 31)
    assert result.pinned == {}
    assert "boundary" not in result.verdict


def test_find_flags_a_best_fit_on_the_box_boundary():
    # The material's density, 3 800 kg/m^3, lies above the box (2 500-3 500): the fit stops
    # at the upper bound and can still look like noise when the bulk densities are uncertain.
    exp = experiment(0.37, 3800.0)
    result = find(model_for(exp), BOX, 31, alpha=1e-6)
    assert result.best.theta["density"] == pytest.approx(3500.0)
    assert result.pinned == {"density": "upper"}
    assert not result.missing
    assert "nothing missing, but theta* sits on the box boundary (density)" in result.verdict
    assert (
        "theta* sits on the boundary of the parameter box (density at its upper bound 3500)"
        in result.sentences[-1]
    )


def test_pinned_parameters_tolerance_and_single_valued_axes():
    box = ParameterBox({"a": (0.0, 1.0), "b": (5.0, 5.0), "c": (10.0, 20.0)})
    assert pinned_parameters({"a": 0.0005, "b": 5.0, "c": 15.0}, box) == {"a": "lower"}
    assert pinned_parameters({"a": 0.002, "b": 5.0, "c": 19.995}, box) == {"c": "upper"}


def test_find_matches_brute_force_over_the_grid():
    exp = experiment(0.5, 3000.0, lambda name, s: 0.1 * 1068.0 / s if name == "mu_psh" else 0.0)
    model = model_for(exp)
    result = find(model, BOX, 21, refine=False)
    grid = BOX.grid(21)
    y = model.observations["measured"].to_numpy()
    sigma = model.observations["sigma"].to_numpy()
    chi2 = np.array([np.sum(((model.predict(t[None])[0] - y) / sigma) ** 2) for t in grid])
    assert result.best.deviance == pytest.approx(chi2.min())
    assert result.gap == pytest.approx(math.sqrt(chi2.min() / len(y)))
    z = (model.predict(grid) - y) / sigma
    assert np.allclose(result.observations["best_abs_z"], np.abs(z).min(axis=0))


def test_find_reports_unreachable_measurements_with_percentage():
    # mu_psh at 1068 Pa is 1.1, the model reaches at most 0.8 (mu_s = 1): 37.5 % above.
    exp = experiment(
        0.5, 3000.0, lambda name, s: 0.6 if (name == "mu_psh" and s == 1068.0) else 0.0
    )
    result = find(model_for(exp), BOX, 21)
    assert result.missing
    sentence = next(s for s in result.sentences if s.startswith("mu_psh"))
    assert "at 1 068 Pa (P = 0.5, 1) is 38 % above anything the model reaches" in sentence
    # The joint fit is pulled towards the unreachable values, away from the other stresses.
    assert "2 029 Pa (P = 0.5, 1); 10 070 Pa (P = 0.5, 1) is reachable alone" in sentence
    assert "sigma above it" in sentence
    row = result.observations.iloc[0]
    assert row["reach_max"] == pytest.approx(0.8)


def test_describe_disagreement_conflict_direction():
    obs = pd.DataFrame(
        {
            "observable": ["rho_b", "rho_b"],
            "normal_stress": [1068.0, 2029.0],
            "P": [1.0, 1.0],
            "measured": [1750.0, 1620.0],
            "sigma": [10.0, 10.0],
            "reach_min": [1300.0, 1300.0],
            "reach_max": [2100.0, 2100.0],
            "z_at_best": [-4.0, 3.0],
        }
    )
    (sentence,) = describe_disagreement(obs)
    assert "rho_b at 1 068 Pa (P = 1) is reachable alone, but the best joint fit stays 4.0 " in (
        sentence
    )
    assert "sigma below it" in sentence and "3.0 sigma above it" in sentence


def test_format_stress_groups_thousands():
    assert format_stress(10070.0) == "10 070 Pa"
    assert format_stress(1068.4) == "1 068 Pa"


def test_find_says_when_the_data_are_too_few_for_a_verdict():
    # Two free parameters, two measured values: the best fit matches both exactly, whatever
    # the material lacks, so Find must not say "nothing missing".
    exp = experiment(0.5, 3000.0, lambda name, s: 0.6 if name == "mu_psh" else 0.0)
    obs = observation_table(exp, {"mu_psh": 0.005, "rho_b": 4.0}, 0.05)
    two = find(SurrogateModel(SURROGATES, obs.iloc[[0, 1]], BOX.names), BOX, 21)
    assert two.n_free == 2 and two.too_few and not two.missing
    assert two.verdict.startswith("2 measured values for 2 free parameters: too few")
    assert "measure at least 3 values" in two.verdict and "4 to name" in two.verdict
    # A third value, unreachable, gives a verdict, with the note that naming needs a fourth.
    three = find(SurrogateModel(SURROGATES, obs.iloc[[0, 1, 2]], BOX.names), BOX, 21)
    assert not three.too_few and three.missing
    assert "naming it needs at least 4 measured values, 3 given" in three.verdict
    # A fixed axis is not a free parameter.
    fixed = ParameterBox({"coefficientFriction": (0.1, 1.0), "density": (3000.0, 3000.0)})
    one = find(SurrogateModel(SURROGATES, obs.iloc[[0, 1]], BOX.names), fixed, 21)
    assert one.n_free == 1 and not one.too_few


def _noisy_model(shift: float, rng: np.random.Generator) -> SurrogateModel:
    """The analytic material at (0.5, 3000) measured with Gaussian noise of the stated sigma,
    mu_psh raised by ``shift`` at the lowest stress (an effect the model lacks)."""
    obs = observation_table(
        experiment(0.5, 3000.0, lambda n, s: shift if (n == "mu_psh" and s == 1068.0) else 0.0),
        {"mu_psh": 0.005, "rho_b": 4.0},
        0.05,
    )
    obs["measured"] = obs["measured"] + obs["sigma"] * rng.standard_normal(len(obs))
    return SurrogateModel(SURROGATES, obs, BOX.names)


def test_find_false_alarm_rate_is_alpha_and_an_effect_is_found():
    # 300 data sets the model describes (N = 12 values, d = 2 parameters): "nothing missing"
    # is rejected in about alpha of them. Binomial(300, 0.05) lies in [4, 29] with probability
    # 0.999, so the test fails by chance about once in a thousand runs (the seeds are fixed).
    rng = np.random.default_rng(11)
    verdicts = [
        find(_noisy_model(0.0, rng), BOX, 21, alpha=0.05, refine=False, draws=199, seed=k)
        for k in range(300)
    ]
    false_alarms = sum(r.missing for r in verdicts)
    assert 4 <= false_alarms <= 29, false_alarms
    p = np.array([r.p_value for r in verdicts])
    # Under "nothing missing" the p-values are uniform: a fifth below 0.2, half below 0.5.
    assert 0.13 <= np.mean(p < 0.2) <= 0.27 and 0.42 <= np.mean(p < 0.5) <= 0.58
    # mu_psh 0.05 (about 3 sigma) too high at one stress in both P: found nearly every time.
    found = [
        find(_noisy_model(0.05, rng), BOX, 21, alpha=0.05, refine=False, draws=199, seed=k).missing
        for k in range(50)
    ]
    assert sum(found) >= 45, sum(found)


def test_bootstrap_p_value_counts_null_draws_at_or_above_the_observed():
    # (1 + #{null >= observed}) / (n + 1), for one value or many; ties count as exceeding.
    null = np.array([4.0, 1.0, 3.0, 2.0])
    assert float(exceedance_p(null, 3.0)) == pytest.approx(3 / 5)
    np.testing.assert_allclose(exceedance_p(null, np.array([0.5, 4.0, 9.0])), [1.0, 2 / 5, 1 / 5])
