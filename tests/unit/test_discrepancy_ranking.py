"""Name step: responses, candidate fits and the BIC ranking on synthetic data with a known truth."""

import math

import numpy as np
import pandas as pd
import pytest

from demcal.core.experiments import Experiment, MeasuredCondition
from demcal.discrepancy.best_fit import ParameterBox
from demcal.discrepancy.effect_response import EffectResponse, response_signature
from demcal.discrepancy.find import find
from demcal.discrepancy.observations import SurrogateModel, observation_table
from demcal.discrepancy.probe_ranking import _power_notes, _power_text, _tested_winner
from demcal.discrepancy.ranking import (
    NamingTest,
    fit_candidate,
    naming_power,
    naming_test,
    null_fit,
    power_with_fixed,
    rank_candidates,
    ranking_sigma,
)

FEATURES = ["coefficientFriction", "density", "normal_stress", "P"]
STRESSES = (1068.0, 2029.0, 10070.0)
BOX = ParameterBox({"coefficientFriction": (0.1, 1.0), "density": (2500.0, 3500.0)})


class Analytic:
    def __init__(self, formula):
        self.formula = formula

    def predict(self, X):
        return self.formula(np.asarray(X, dtype=float))


SURROGATES = {
    "mu_psh": (Analytic(lambda X: 0.2 + 0.6 * X[:, 0]), FEATURES),
    "rho_b": (Analytic(lambda X: X[:, 1] * (0.62 - 0.08 * X[:, 0])), FEATURES),
}


def cohesion_effect(name: str, stress: float) -> float:
    """A cohesion-like effect per unit magnitude: strongest at low stress."""
    return (0.1 if name == "mu_psh" else 80.0) * 1068.0 / stress


def uniform_effect(name: str, stress: float) -> float:
    """An effect the current model can mimic (a shift absorbed by the parameters)."""
    return 0.08 if name == "mu_psh" else -40.0


def setup(magnitude: float):
    """Model, grid and predictions for data with a cohesion-like effect of ``magnitude``."""
    conds = []
    for stress in STRESSES:
        for p in (0.5, 1.0):
            values = {
                "mu_psh": 0.2 + 0.6 * 0.45 + magnitude * cohesion_effect("mu_psh", stress),
                "rho_b": 2900.0 * (0.62 - 0.08 * 0.45)
                + magnitude * cohesion_effect("rho_b", stress),
            }
            conds.append(MeasuredCondition(values, {"mu_psh": 0.01, "rho_b": 8.0}, stress, p))
    obs = observation_table(Experiment("m", "", conds), {"mu_psh": 0.005, "rho_b": 4.0}, 0.05)
    model = SurrogateModel(SURROGATES, obs, BOX.names)
    grid = BOX.grid(31)
    return model, grid, model.predict(grid)


def response_of(effect, model: SurrogateModel, levels=(1.0, 2.0), name="x") -> EffectResponse:
    """Exact 'DEM' response: linear in the magnitude."""
    obs = model.observations
    unit = np.array([effect(r.observable, r.normal_stress) for r in obs.itertuples()])
    base = np.full(len(obs), 1.0)
    values = np.vstack([base] + [base + level * unit for level in levels])
    return EffectResponse.from_runs(name, [0.0, *levels], values, reference=0)


def test_response_interpolates_between_levels():
    resp = EffectResponse.from_runs(
        "c", [4.0, 0.0, 2.0], np.array([[5.0, 1.0], [1.0, 1.0], [2.0, 3.0]]), reference=1
    )
    assert list(resp.magnitudes) == [0.0, 2.0, 4.0]
    assert resp.reference == 0 and resp.off == 0.0
    assert resp.at(0.0) == pytest.approx([0.0, 0.0])
    assert resp.at(2.0) == pytest.approx([1.0, 2.0])
    assert resp.at(3.0) == pytest.approx([2.5, 1.0])
    # Beyond the probed span the response is held at the end value.
    assert resp.at(9.0) == pytest.approx([4.0, 0.0])


def test_response_drops_levels_equal_to_the_reference():
    resp = EffectResponse.from_runs(
        "w", [0.5, 0.5, 0.8], np.array([[1.0], [9.0], [2.0]]), reference=0
    )
    assert list(resp.magnitudes) == [0.5, 0.8]
    assert resp.at(0.8) == pytest.approx([1.0])


def test_integer_candidate_tries_whole_magnitudes():
    resp = EffectResponse.from_runs(
        "p", [1.0, 3.0], np.array([[0.0], [1.0]]), reference=0, integer=True
    )
    assert list(resp.trial_magnitudes(41)) == [1.0, 2.0, 3.0]


def test_fit_recovers_the_hidden_magnitude():
    model, grid, F = setup(magnitude=1.4)
    weights = model.observations["sigma"].to_numpy()
    fit = fit_candidate(model, BOX, grid, F, response_of(cohesion_effect, model), weights)
    assert fit.magnitude == pytest.approx(1.4, abs=0.06)
    assert fit.best.theta["coefficientFriction"] == pytest.approx(0.45, abs=0.01)
    assert fit.best.deviance < 1.0


def test_ranking_weights_count_the_scatter_of_replicate_means():
    # The response is mean(n_p probe runs) - mean(n_ref reference runs): its scatter, drawn
    # here, is what the weights add to sigma.
    rng = np.random.default_rng(5)
    noise = np.array([0.05, 20.0])
    sigma = np.array([0.03, 10.0])
    for n_p, n_ref in ((1, 1), (1, 3), (3, 3)):
        draws = rng.normal(0.0, noise, (40_000, n_p, 2)).mean(axis=1) - rng.normal(
            0.0, noise, (40_000, n_ref, 2)
        ).mean(axis=1)
        expected = np.sqrt(sigma**2 + draws.var(axis=0))
        assert ranking_sigma(sigma, noise, n_p, n_ref) == pytest.approx(expected, rel=0.01)
    assert ranking_sigma(sigma, noise) == pytest.approx(np.sqrt(sigma**2 + 2 * noise**2))
    with pytest.raises(ValueError, match="at least 1"):
        ranking_sigma(sigma, noise, 0, 3)


def test_ranking_names_the_effect_that_explains_the_gap():
    model, grid, F = setup(magnitude=1.0)
    noise = model.observations["surrogate_rmse"].to_numpy()
    weights = ranking_sigma(model.observations["sigma"].to_numpy(), noise)
    null = null_fit(model, BOX, grid, F, weights)
    fits = {
        name: fit_candidate(model, BOX, grid, F, response_of(effect, model, name=name), weights)
        for name, effect in (("cohesion", cohesion_effect), ("uniform", uniform_effect))
    }
    table, winner = rank_candidates(null.deviance, fits, len(model.observations), 0.5)
    assert winner == "cohesion"
    top = table.iloc[0]
    assert top["candidate"] == "cohesion" and top["rank"] == 1 and top["named"]
    n = len(model.observations)
    assert top["delta_bic"] == pytest.approx(null.deviance - top["deviance"] - math.log(n))
    assert top["explained"] > 0.9
    uniform = table.set_index("candidate").loc["uniform"]
    assert uniform["explained"] < 0.5 and not uniform["named"]


def test_ranking_scores_no_gain_without_an_effect():
    # Whether the leader is named is the bootstrap's call (test_naming_* below); here
    # the score: with nothing hidden the candidate removes no misfit and pays ln N.
    model, grid, F = setup(magnitude=0.0)
    weights = model.observations["sigma"].to_numpy()
    null = null_fit(model, BOX, grid, F, weights)
    assert null.deviance < 1e-3
    resp = response_of(cohesion_effect, model)
    fits = {"cohesion": fit_candidate(model, BOX, grid, F, resp, weights)}
    table, _ = rank_candidates(null.deviance, fits, len(model.observations))
    n = len(model.observations)
    assert table["delta_bic"].iloc[0] == pytest.approx(-math.log(n), abs=1e-3)


def test_ranking_requires_a_share_of_the_misfit():
    model, grid, F = setup(magnitude=1.0)
    weights = model.observations["sigma"].to_numpy()
    null = null_fit(model, BOX, grid, F, weights)
    # Explains the friction part of the hidden effect, not the density part.
    resp = response_of(lambda name, s: cohesion_effect(name, s) * (name == "mu_psh"), model)
    fits = {"partial": fit_candidate(model, BOX, grid, F, resp, weights)}
    n = len(model.observations)
    table, _ = rank_candidates(null.deviance, fits, n, 0.0)
    share = float(table["explained"].iloc[0])
    assert 0.0 < share < 1.0
    _, named_low = rank_candidates(null.deviance, fits, n, share - 1e-9)
    _, named_high = rank_candidates(null.deviance, fits, n, share + 1e-3)
    assert named_low == "partial" and named_high is None


def test_null_fit_with_find_weights_equals_find():
    model, grid, F = setup(magnitude=1.0)
    weights = model.observations["sigma"].to_numpy()
    result = find(model, BOX, 31)
    assert null_fit(model, BOX, grid, F, weights).deviance == pytest.approx(
        result.best.deviance, rel=1e-6
    )


def test_signature_of_a_cohesion_like_response():
    model, _, _ = setup(magnitude=0.0)
    resp = response_of(cohesion_effect, model, levels=(1.0,))
    ref = np.where(model.observations["observable"] == "rho_b", 1700.0, 0.6)
    noise = np.where(model.observations["observable"] == "rho_b", 4.0, 0.005)
    text = response_signature(model.observations, resp, ref, noise)
    assert "mu_psh +0.10 at 1 068 Pa, +0.05 at 2 029 Pa, +0.01 at 10 070 Pa" in text
    assert "apparent friction falls with normal stress" in text
    assert "rho_b +4.7 % at 1 068 Pa" in text


def test_signature_ignores_responses_within_the_noise():
    model, _, _ = setup(magnitude=0.0)
    resp = response_of(uniform_effect, model, levels=(0.01,))
    noise = np.where(model.observations["observable"] == "rho_b", 4.0, 0.005)
    text = response_signature(model.observations, resp, np.full(len(noise), 1.0), noise)
    assert text == "mu_psh no clear change; rho_b no clear change"


# --- the bootstrap naming tests, on a linear model with known truths ---------------------------

_K = 8
_THETA = np.linspace(0.0, 1.0, 41)
_GRID = np.outer(_THETA, np.linspace(1.0, 2.0, _K))  # the current model: f_k(t) = t * (1 + k/7)
_W = np.full(_K, 0.05)


def _response(name: str, shape: np.ndarray) -> EffectResponse:
    # Probe levels 1 and 2 of an effect that shifts the values by magnitude * shape.
    return EffectResponse.from_runs(name, [0.0, 1.0, 2.0], np.outer([0.0, 1.0, 2.0], shape), 0)


_A = _response("a", np.where(np.arange(_K) < 4, 0.15, 0.0))  # acts on the first half only
_B = _response("b", np.linspace(0.15, -0.15, _K))  # a tilt across all values
_C = _response("c", np.where(np.arange(_K) < 4, 0.15, 0.0) + 1e-4)  # a copy of a


def _data(rng, truth: np.ndarray) -> np.ndarray:
    return truth + _W * rng.standard_normal(_K)


def test_naming_false_alarm_rate_is_alpha_without_an_effect():
    # 200 data sets of the current model at t = 0.5: the best of two candidates is named in
    # about alpha of them. Binomial(200, 0.05) lies in [2, 21] with probability 0.999.
    rng = np.random.default_rng(5)
    tests = [
        naming_test(_GRID, _data(rng, _GRID[20]), _W, {"a": _A, "b": _B}, 41, 199, seed=k)
        for k in range(200)
    ]
    alarms = sum(t.p_effect < 0.05 for t in tests)
    assert 2 <= alarms <= 21, alarms


def test_naming_finds_the_hidden_effect_and_tells_it_from_the_runner_up():
    rng = np.random.default_rng(6)
    truth = _GRID[20] + _A.at(1.8)  # 0.27 (5.4 sigma) on four values
    tests = [
        naming_test(_GRID, _data(rng, truth), _W, {"a": _A, "b": _B}, 41, 199, k) for k in range(40)
    ]
    named = [t for t in tests if t.top == "a" and t.p_effect < 0.05 and t.p_runner_up < 0.05]
    assert len(named) >= 36, [(t.top, t.p_effect, t.p_runner_up) for t in tests]
    assert all(t.runner_up == "b" for t in named)


def test_naming_reports_two_candidates_that_cannot_be_told_apart():
    # c acts like a: the data cannot separate them, so naming must not pick one, and the value
    # that separates them best is one where they differ (the second half, where c adds 1e-4).
    rng = np.random.default_rng(7)
    truth = _GRID[20] + _A.at(1.3)
    tests = [
        naming_test(_GRID, _data(rng, truth), _W, {"a": _A, "c": _C}, 41, 199, k) for k in range(40)
    ]
    assert all(t.p_effect < 0.05 for t in tests)
    ambiguous = [t for t in tests if t.p_runner_up >= 0.05]
    assert len(ambiguous) >= 36, [t.p_runner_up for t in tests]


def test_naming_decision_records_the_pair_it_cannot_tell_apart():
    obs = pd.DataFrame({"observable": ["mu_psh"], "normal_stress": [1068.0], "P": [0.5]})
    notes: list[str] = []
    # The runner-up fits as well: not named, and the two are the ambiguous pair.
    both = NamingTest("rolling", 0.001, "cohesion", 0.145, 0, 1000)
    assert _tested_winner("rolling", both, 0.05, obs, notes) == (None, ("rolling", "cohesion"))
    assert "rolling and cohesion cannot be told apart" in notes[-1]
    # Noise alone explains as much: not named, and no pair.
    noise = NamingTest("rolling", 0.2, "cohesion", 0.5, 0, 1000)
    assert _tested_winner("rolling", noise, 0.05, obs, notes) == (None, None)
    # Both tests reject: named.
    clear = NamingTest("rolling", 0.001, "cohesion", 0.01, 0, 1000)
    assert _tested_winner("rolling", clear, 0.05, obs, notes) == ("rolling", None)


def test_naming_power_is_the_rate_at_which_the_test_names_the_effect():
    # A weak effect on half the values (1 and 2 sigma per value at its two levels), a tilt the
    # grid cannot follow, and a shift along the model's own gradient that the parameter absorbs.
    weak = _response("a", np.where(np.arange(_K) < 4, 0.05, 0.0))
    absorbed = _response("u", 0.1 * np.linspace(1.0, 2.0, _K))
    responses = {"a": weak, "b": _B, "u": absorbed}
    power = naming_power(_GRID, _GRID[20], _W, responses, 0.05, 41, 400, 999, seed=3)
    power = power.set_index(["candidate", "magnitude"])
    # The absorbed effect is found only at the false-alarm rate and never leads: these data
    # cannot name it at any magnitude. The tilt is named nearly always.
    assert power.loc[("u", 2.0), "named"] == 0.0 and power.loc[("u", 2.0), "found"] <= 0.1
    assert power.loc[("b", 2.0), "named"] >= 0.95
    # The shares are what the naming test does on data drawn with the effect present: found and
    # leading in about the same share of 100 data sets (binomial sd <= 0.05).
    rng = np.random.default_rng(9)
    for level in (1.0, 2.0):
        tests = [
            naming_test(_GRID, _data(rng, _GRID[20] + weak.at(level)), _W, responses, 41, 199, k)
            for k in range(100)
        ]
        rate = np.mean([t.p_effect < 0.05 and t.top == "a" for t in tests])
        expected = power.loc[("a", level), "named"]
        assert 0.2 < expected < 0.8 and abs(rate - expected) <= 0.15, (level, rate, expected)
    # The naming test's own null distribution serves as well (the Name step reuses it).
    null = naming_test(_GRID, _GRID[20], _W, responses, 41, 999, seed=4).null_drops
    assert null.shape == (999,)
    again = naming_power(_GRID, _GRID[20], _W, responses, 0.05, 41, 400, seed=3, null_drops=null)
    shift = again.set_index(["candidate", "magnitude"])["named"] - power["named"]
    assert shift.abs().max() <= 0.1, shift


def test_fixing_the_parameter_that_absorbs_an_effect_makes_it_nameable():
    # Two parameters: t1 moves every value alike, t2 alternates. Candidate u shifts the values
    # exactly as t2 does (0.2 of t2 per unit magnitude), so with t2 free it is absorbed; held
    # at its best value (as a separate measurement of it would), u is plain. Holding t1 does
    # not help.
    axis = np.linspace(0.0, 1.0, 21)
    grid = np.array([(a, b) for a in axis for b in axis])
    up = np.ones(_K)
    alternate = np.where(np.arange(_K) % 2 == 0, 1.0, -1.0)
    predictions = np.outer(grid[:, 0], up) + np.outer(grid[:, 1], alternate)
    responses = {"u": _response("u", 0.2 * alternate), "b": _B}
    y = predictions[int(np.flatnonzero((grid[:, 0] == 0.5) & (grid[:, 1] == 0.25))[0])]
    free = naming_power(predictions, y, _W, responses, 0.05, 41, 200, 999, only="u")
    assert free["named"].max() <= 0.05 and set(free["candidate"]) == {"u"}
    held = power_with_fixed(
        grid, predictions, ["t1", "t2"], y, _W, responses, "u", 0.05, 41, 200, 999
    )
    assert held["t2"] >= 0.95 and held["t1"] <= 0.05, held
    with pytest.raises(ValueError, match="not a candidate"):
        naming_power(predictions, y, _W, responses, 0.05, only="x")


def test_power_notes_name_the_candidates_the_data_cannot_name():
    power = pd.DataFrame(
        {
            "candidate": ["cohesion"] * 3 + ["polydispersity"] * 3,
            "magnitude": [15000.0, 40000.0, 65000.0, 2.0, 4.0, 6.0],
            "found": [0.4, 0.9, 1.0, 0.1, 0.6, 0.3],
            "named": [0.27, 0.84, 1.0, 0.06, 0.36, 0.2],
        }
    )
    assert _power_text(power) == {
        "cohesion": "1.5e+04: 27 %, 4e+04: 84 %, 6.5e+04: 100 %",
        "polydispersity": "2: 6 %, 4: 36 %, 6: 20 %",
    }
    (note,) = _power_notes(power)
    assert note.startswith("polydispersity could not be named from these measurements")
    assert "probe level 4: data sets drawn with it there show an effect in 60 %" in note
    # With the powers of one parameter held at a time: which measurement would help, if any.
    helps = {"polydispersity": {"density": 0.8, "coefficientFriction": 0.1}}
    (note,) = _power_notes(power, helps)
    assert note.endswith(
        "it could be named with density measured on its own (up to 80 % with density held at "
        "its best-fit value)"
    )
    nothing = {"polydispersity": {"density": 0.47, "coefficientFriction": 0.1}}
    (note,) = _power_notes(power, nothing)
    assert note.endswith("does not change that (at most 47 %, with density held)")
