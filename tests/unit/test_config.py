"""Configuration schema: defaults, and errors that name the offending key."""

from pathlib import Path

import pytest
import yaml
from snakemake.utils import update_config

from demcal.core.config import (
    ConfigError,
    load_config,
    load_schema,
    parameter_problems,
    validate_config,
    with_overrides,
)
from demcal.core.parameters import (
    CASE_PARAMETERS,
    CONTACT_PARAMETERS,
    ELASTIC_PARAMETERS,
    GEOMETRY_PARAMETERS,
    OPTIONAL_CONTACT_PARAMETERS,
    PARAMETER_LABELS,
    PARAMETERS,
    closest_parameter,
    out_of_bounds,
)
from demcal.design.cases import verification_engines, verification_threads
from demcal.virtual_tests.deck import DECK_NAMES, render_case

ROOT = Path(__file__).resolve().parents[2]


def _walk(schema: dict, path: str = ""):
    for name, sub in schema.get("properties", {}).items():
        yield f"{path}{name}", sub
        yield from _walk(sub, f"{path}{name}.")


def test_every_key_has_description_and_default():
    schema = load_schema("config.schema.yaml")
    for key, sub in _walk(schema):
        assert sub.get("description"), f"{key} has no description"
        assert "default" in sub, f"{key} has no default"


_ABSENT = object()


def _lookup(tree, path):
    """Value at ``path``; ``_ABSENT`` if a key is missing, None below a non-mapping."""
    for key in path:
        if not isinstance(tree, dict):
            return None
        if key not in tree:
            return _ABSENT
        tree = tree[key]
    return tree


def _file_leaves(tree: dict, path: tuple = ()):
    for key, value in tree.items():
        if isinstance(value, dict) and value:
            yield from _file_leaves(value, (*path, key))
        else:
            yield (*path, key), value


def _schema_leaves(schema: dict, path: tuple = ()):
    for name, sub in schema.get("properties", {}).items():
        if "properties" in sub:
            yield from _schema_leaves(sub, (*path, name))
        else:
            yield (*path, name), sub["default"]


@pytest.mark.parametrize("name", ["config.yaml", "tiny.yaml", "paper.yaml"])
def test_shipped_configs_are_valid(name):
    raw = yaml.safe_load((ROOT / "config" / name).read_text())
    cfg = load_config(ROOT / "config" / name)
    # Every value the file sets comes through validation unchanged (list entries may gain
    # their defaults) ...
    for path, value in _file_leaves(raw):
        _assert_kept(_lookup(cfg, path), value, path)
    # ... and every setting it leaves out has the schema's default.
    defaulted = 0
    for path, default in _schema_leaves(load_schema("config.schema.yaml")):
        if _lookup(raw, path) is _ABSENT:
            _assert_kept(_lookup(cfg, path), default, path)
            defaulted += 1
    assert defaulted > 20


def _assert_kept(got, value, path: tuple) -> None:
    if isinstance(value, list) and value and isinstance(value[0], dict):
        assert len(got) == len(value), path
        for item, full in zip(value, got, strict=True):
            assert {k: full[k] for k in item} == item, path
    else:
        assert got == value, path


def test_defaults_fill_missing_sections():
    cfg = validate_config({}, "empty")
    assert cfg["engine"]["threads"] == 1
    assert cfg["design"]["ranges"]["coefficientRestitution"] == [0.5, 0.9]


def test_unknown_key_is_named():
    with pytest.raises(ConfigError) as err:
        validate_config({"design": {"nn": 4}}, "my.yaml")
    assert "my.yaml" in str(err.value)
    assert "'nn'" in str(err.value) and "design" in str(err.value)


def test_out_of_range_value_names_key():
    with pytest.raises(ConfigError, match=r"engine\.threads"):
        validate_config({"engine": {"threads": 0}}, "my.yaml")


def test_malformed_yaml_names_file(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("design: [unclosed\n")
    with pytest.raises(ConfigError, match=r"bad\.yaml"):
        load_config(bad)


def test_verification_engines_default_to_the_configured_engine():
    cfg = validate_config({"engine": {"command": "liggghts -in {deck}", "threads": 3}}, "x")
    assert verification_engines(cfg) == {"configured": "liggghts -in {deck}"}
    assert verification_threads(cfg) == 3
    engines = {"bundled": "dem_engine -in {deck}", "liggghts": "liggghts -in {deck}"}
    cfg = validate_config({"verification": {"engines": engines, "threads": 2}}, "x")
    assert list(verification_engines(cfg)) == ["bundled", "liggghts"]
    assert verification_threads(cfg) == 2


@pytest.mark.parametrize("name", ["LIGGGHTS", "my-engine", "2nd", "shear_cell", ""])
def test_verification_engine_names_are_path_safe(name):
    with pytest.raises(ConfigError, match=r"verification\.engines"):
        validate_config({"verification": {"engines": {name: "liggghts -in {deck}"}}}, "x")


def test_all_errors_reported_at_once():
    with pytest.raises(ConfigError) as err:
        validate_config({"seed": -1, "design": {"kind": "grid"}}, "x.yaml")
    text = str(err.value)
    assert "seed" in text and "design.kind" in text


# --- contact-parameter names and bounds ----------------------------------------------------


def test_misspelt_design_range_is_named_with_a_suggestion():
    with pytest.raises(ConfigError) as err:
        validate_config({"design": {"ranges": {"coefficientFrction": [0.1, 0.9]}}}, "my.yaml")
    text = str(err.value)
    assert text.startswith("my.yaml: invalid configuration:")
    assert (
        "design.ranges.coefficientFrction: unknown contact parameter "
        "(did you mean coefficientFriction?)" in text
    )


def test_every_out_of_bounds_design_value_is_reported_at_once():
    cfg = {
        "design": {
            "kind": "factorial",
            "levels": {"coefficientFriction": [-0.2, 0.4], "density": [2500.0, 0.0]},
            "ranges": {"coefficientRestitution": [0.5, 1.5]},
            "fixed": {"cohesionEnergyDensity": -1.0},
        }
    }
    with pytest.raises(ConfigError) as err:
        validate_config(cfg, "x.yaml")
    lines = str(err.value).splitlines()[1:]
    assert [line.strip() for line in lines] == [
        "design.ranges.coefficientRestitution[1]: coefficientRestitution = 1.5 is outside "
        "(0.05, 1]",
        "design.levels.coefficientFriction[0]: coefficientFriction = -0.2 is outside [0, inf)",
        "design.levels.density[1]: density = 0 is outside (0, inf)",
        "design.fixed.cohesionEnergyDensity: cohesionEnergyDensity = -1 is outside [0, inf)",
        "design.levels.coefficientFriction: must stay above 0, got -0.2 (the surrogates take "
        "the logarithm of this input; start the range at e.g. 0.05)",
    ]


def test_sliding_friction_reaching_zero_is_refused_before_any_run():
    # Allowed for LIGGGHTS, but the surrogates read ln(mu_s): the study would stop at training.
    cfg = {
        "design": {"ranges": {"coefficientFriction": [0.0, 1.0]}},
        "screening": {"axes": {"coefficientFriction": [0.0, 1.0, 50]}},
    }
    with pytest.raises(ConfigError) as err:
        validate_config(cfg, "x.yaml")
    lines = [line.strip() for line in str(err.value).splitlines()[1:]]
    assert [line.split(":")[0] for line in lines] == [
        "design.ranges.coefficientFriction",
        "screening.axes.coefficientFriction",
    ]
    assert all("must stay above 0, got 0" in line for line in lines)
    # A fixed value does not vary, is no surrogate input and may be 0.
    validate_config({"design": {"fixed": {"coefficientFriction": 0.0}}}, "x.yaml")


def test_rolling_friction_varied_without_the_rolling_model_is_refused():
    # The default design varies coefficientRollingFriction; with the model off it does nothing.
    with pytest.raises(ConfigError) as err:
        validate_config({"material": {"rolling_friction": False}}, "x.yaml")
    lines = [line.strip() for line in str(err.value).splitlines()[1:]]
    assert len(lines) == 1
    assert lines[0].startswith("design.ranges.coefficientRollingFriction: varied, but ")
    assert "material.rolling_friction is false" in lines[0]
    factorial = {
        "kind": "factorial",
        "levels": {"coefficientFriction": [0.3, 0.6], "coefficientRollingFriction": [0.1, 0.4]},
    }
    with pytest.raises(ConfigError, match=r"design\.levels\.coefficientRollingFriction: varied"):
        validate_config({"material": {"rolling_friction": False}, "design": factorial}, "x.yaml")
    # Held at one value, or read by no design kind (a factorial design ignores the ranges),
    # it is accepted; so is any range with the rolling model on.
    fixed = {
        "ranges": {"coefficientFriction": [0.1, 0.9]},
        "fixed": {"coefficientRollingFriction": 0.0},
    }
    validate_config({"material": {"rolling_friction": False}, "design": fixed}, "x.yaml")
    factorial["levels"]["coefficientRollingFriction"] = [0.0]
    validate_config({"material": {"rolling_friction": False}, "design": factorial}, "x.yaml")
    validate_config({"material": {"rolling_friction": True}}, "x.yaml")


@pytest.mark.parametrize(
    ("low", "high", "valid"),
    [(0.06, 1.0, True), (0.05, 0.9, False), (0.5, 1.0000001, False)],
)
def test_restitution_range_follows_liggghts_bounds(low, high, valid):
    cfg = validate_config({}, "x.yaml")
    cfg["design"]["ranges"]["coefficientRestitution"] = [low, high]
    problems = parameter_problems(cfg)
    assert (problems == []) is valid


def test_unknown_name_without_a_close_match_lists_the_known_names():
    with pytest.raises(
        ConfigError,
        match=r"design\.choices\.colour: unknown contact parameter "
        r"\(known: coefficientFriction, .*dCylDp\)",
    ):
        validate_config({"design": {"choices": {"colour": [1.0, 2.0]}}}, "x.yaml")


def test_screening_axes_are_checked_by_name_and_range():
    axes = {"coefficientRollingFrictoin": [0.1, 1.0, 10], "density": [-5.0, 3500.0, 4]}
    with pytest.raises(ConfigError) as err:
        validate_config({"screening": {"axes": axes}}, "x.yaml")
    text = str(err.value)
    assert (
        "screening.axes.coefficientRollingFrictoin: unknown contact parameter "
        "(did you mean coefficientRollingFriction?)" in text
    )
    assert "screening.axes.density[0]: density = -5 is outside (0, inf)" in text


def test_discrepancy_candidates_are_checked_unless_they_set_a_config_key():
    candidates = [
        {
            "name": "cohesion",
            "description": "d",
            "parameter": "cohesionEnergyDensty",
            "off_value": 0.0,
            "range": [0.0, 1.0e4],
            "probe_levels": [5.0e3],
        },
        {
            "name": "wall",
            "description": "d",
            "parameter": "wallFriction",
            "off_value": "coefficientFricton",
            "range": [-0.1, 1.0],
            "probe_levels": [0.2],
        },
        {
            "name": "size",
            "description": "d",
            "parameter": "sizeClasses",
            "config_key": "particles.classes",
            "off_value": 1,
            "range": [1, 3],
            "probe_levels": [3],
        },
    ]
    with pytest.raises(ConfigError) as err:
        validate_config({"discrepancy": {"candidates": candidates}}, "x.yaml")
    lines = [line.strip() for line in str(err.value).splitlines()[1:]]
    assert lines == [
        "discrepancy.candidates[0].parameter: 'cohesionEnergyDensty': unknown contact parameter "
        "(did you mean cohesionEnergyDensity?)",
        "discrepancy.candidates[1].range[0]: wallFriction = -0.1 is outside [0, inf)",
        "discrepancy.candidates[1].off_value: 'coefficientFricton': unknown contact parameter "
        "(did you mean coefficientFriction?)",
    ]


@pytest.mark.parametrize("name", ["config.yaml", "tiny.yaml", "paper.yaml"])
def test_shipped_configs_have_no_parameter_problems(name):
    assert parameter_problems(load_config(ROOT / "config" / name)) == []


def test_schema_bounds_of_parameters_agree_with_the_parameter_table():
    """Where the schema bounds a parameter itself, it must say what core.parameters says."""
    schema = load_schema("config.schema.yaml")["properties"]
    bounded = {
        **schema["application"]["properties"]["parameters"]["properties"],
        "poissonsRatio": schema["material"]["properties"]["poissonsRatio"],
        "youngsModulus": schema["material"]["properties"]["youngsModulus"],
    }
    for name, sub in bounded.items():
        bounds = PARAMETERS[name].bounds
        if "minimum" in sub:
            assert (sub["minimum"], True) == (bounds.low, bounds.low_closed), name
        else:
            assert (sub["exclusiveMinimum"], False) == (bounds.low, bounds.low_closed), name
        if "maximum" in sub:
            assert (sub["maximum"], True) == (bounds.high, bounds.high_closed), name
        elif "exclusiveMaximum" in sub:
            assert (sub["exclusiveMaximum"], False) == (bounds.high, bounds.high_closed), name
        else:
            assert bounds.high == float("inf"), name


def test_parameter_bounds_and_suggestions():
    assert out_of_bounds("coefficientRestitution", 1.0) is None
    assert out_of_bounds("coefficientRestitution", 0.05) == (
        "coefficientRestitution = 0.05 is outside (0.05, 1]"
    )
    assert out_of_bounds("poissonsRatio", 0.5) == "poissonsRatio = 0.5 is outside (0, 0.5)"
    assert out_of_bounds("density", float("nan")) == "density = nan is not a number"
    assert out_of_bounds("wallFriction", True) == "wallFriction = True is not a number"
    assert closest_parameter("COEFFICIENTFRICTION") == "coefficientFriction"
    assert closest_parameter("youngModulus") == "youngsModulus"
    assert closest_parameter("temperature") is None


def test_parameter_groups_cover_the_table_in_its_order():
    groups = (
        *CONTACT_PARAMETERS,
        *OPTIONAL_CONTACT_PARAMETERS,
        *ELASTIC_PARAMETERS,
        *GEOMETRY_PARAMETERS,
    )
    assert groups == CASE_PARAMETERS == tuple(PARAMETERS)
    assert PARAMETER_LABELS == {
        "coefficientFriction": "mu_s (-)",
        "coefficientRollingFriction": "mu_r (-)",
        "coefficientRestitution": "COR (-)",
        "density": "rho_p (kg/m^3)",
    }


def _alone_and_merged(profile: str) -> tuple[dict, dict]:
    """config/PROFILE.yaml validated alone (as load_config reads it) and merged over
    config/config.yaml (as Snakemake reads `--configfile config/PROFILE.yaml`)."""
    path = ROOT / "config" / f"{profile}.yaml"
    alone = validate_config(yaml.safe_load(path.read_text()), f"{path} alone")
    merged = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    update_config(merged, yaml.safe_load(path.read_text()))
    return alone, validate_config(merged, f"{path} over config/config.yaml")


def test_tiny_renders_the_same_decks_alone_and_merged_over_the_quick_profile(tmp_path):
    # Snakemake merges `--configfile config/tiny.yaml` over config/config.yaml; the scripts and
    # the discrepancy matrix read tiny.yaml alone. Both must give the same virtual tests, or
    # data made one way are fitted by a model made the other way.
    tiny, merged = _alone_and_merged("tiny")
    case = {
        "case_id": "c0001",
        "coefficientFriction": 0.5,
        "coefficientRollingFriction": 0.3,
        "coefficientRestitution": 0.6,
        "density": 3000.0,
        "normal_stress": 2029.0,
    }
    for test, row in (("shear_cell", case), ("angle_of_repose", case)):
        decks = []
        for name, data in (("alone", tiny), ("merged", merged)):
            out = tmp_path / name / test
            render_case(test, row, data, out)
            decks.append((out / DECK_NAMES[test]).read_text())
        assert decks[0] == decks[1], test


# Keys a profile may leave to config/config.yaml without effect: tiny's particles are
# monodisperse (no sieve classes to scale or cut), and the modulus cap binds neither tiny
# (1000 x 2029 Pa) nor paper (no stress-scaled modulus). Paper's discrepancy candidates are
# the quick profile's under Snakemake (the paper profile has no discrepancy section), and its
# factorial design has no heap-only sets.
WITHOUT_EFFECT = {
    "tiny": {"particles.scale", "particles.classes", "shear_cell.youngs_modulus_max"},
    "paper": {
        "shear_cell.youngs_modulus_max",
        "discrepancy.candidates",
        "design.repose_extra_sets",
        "design.shear_extra_sets",
        "design.shared_stresses",
    },
}


def _differences(a: object, b: object, path: str = "") -> set[str]:
    """Dotted keys whose values differ between two nested mappings."""
    if isinstance(a, dict) and isinstance(b, dict):
        out: set[str] = set()
        for key in set(a) | set(b):
            out |= _differences(a.get(key), b.get(key), f"{path}.{key}" if path else key)
        return out
    return set() if a == b else {path}


@pytest.mark.parametrize("profile", sorted(WITHOUT_EFFECT))
def test_a_profile_reads_the_same_alone_and_merged_over_the_quick_profile(profile: str) -> None:
    # Snakemake merges `--configfile config/PROFILE.yaml` over config/config.yaml; scripts
    # and tests read the profile alone (load_config). Every key with an effect must agree.
    alone, merged = _alone_and_merged(profile)
    assert _differences(alone, merged) <= WITHOUT_EFFECT[profile]


def test_overrides_are_validated_like_the_file():
    base = load_config(ROOT / "config" / "config.yaml")
    cfg = with_overrides(base, ["shear_cell.contact_snapshots=25", "shear_cell.P=[0.5, 1.0]"], "c")
    assert cfg["shear_cell"]["contact_snapshots"] == 25
    assert cfg["shear_cell"]["P"] == [0.5, 1.0]
    # The configuration given stays as it was.
    assert base["shear_cell"]["contact_snapshots"] == 0
    with pytest.raises(ConfigError, match=r"c with --set shear_cell\.contact_snapshot=5"):
        with_overrides(base, ["shear_cell.contact_snapshot=5"], "c")
    with pytest.raises(ConfigError, match="contact_snapshots"):
        with_overrides(base, ["shear_cell.contact_snapshots=-1"], "c")
    with pytest.raises(ConfigError, match=r"expected SECTION\.KEY=VALUE"):
        with_overrides(base, ["contact_snapshots=5"], "c")
