"""Configuration schema: defaults, and errors that name the offending key."""

from pathlib import Path

import pytest

from demcal.core.config import ConfigError, load_config, load_schema, validate_config

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


@pytest.mark.parametrize("name", ["config.yaml", "tiny.yaml"])
def test_shipped_configs_are_valid(name):
    cfg = load_config(ROOT / "config" / name)
    assert cfg["design"]["kind"] in {"factorial", "random", "lhs", "sobol"}


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


def test_all_errors_reported_at_once():
    with pytest.raises(ConfigError) as err:
        validate_config({"seed": -1, "design": {"kind": "grid"}}, "x.yaml")
    text = str(err.value)
    assert "seed" in text and "design.kind" in text
