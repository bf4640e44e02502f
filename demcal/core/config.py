"""Loading and validating workflow configuration against the JSON schema.

The schema (``workflow/schemas/config.schema.yaml``, JSON Schema draft 2020-12) gives every key
a description and a default; validation fills the defaults in and reports every problem with the
dotted key path, so a typo or an out-of-range value stops the workflow before anything runs.
"""

from __future__ import annotations

import copy
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import jsonschema
import yaml

SCHEMA_DIR = Path(__file__).resolve().parents[2] / "workflow" / "schemas"


class ConfigError(ValueError):
    """A configuration file or value that does not match its schema."""


def _with_defaults(validator_class: type[jsonschema.protocols.Validator]) -> type:
    """Extend a validator class so that validation also fills in schema defaults."""
    validate_properties = validator_class.VALIDATORS["properties"]

    def set_defaults(
        validator: Any, properties: Mapping, instance: Any, schema: Mapping
    ) -> Iterator[jsonschema.ValidationError]:
        if isinstance(instance, dict):
            for name, sub in properties.items():
                if isinstance(sub, dict) and "default" in sub and name not in instance:
                    instance[name] = copy.deepcopy(sub["default"])
        yield from validate_properties(validator, properties, instance, schema)

    return jsonschema.validators.extend(validator_class, {"properties": set_defaults})


def load_schema(name: str) -> dict:
    """Read a schema file from ``workflow/schemas``.

    Parameters
    ----------
    name : str
        File name, e.g. ``"config.schema.yaml"``.
    """
    path = SCHEMA_DIR / name
    with path.open() as fh:
        return yaml.safe_load(fh)


def _key_path(error: jsonschema.ValidationError) -> str:
    parts = [str(p) for p in error.absolute_path]
    return ".".join(parts) if parts else "(top level)"


def _describe(error: jsonschema.ValidationError) -> str:
    if error.validator == "additionalProperties":
        allowed = sorted(error.schema.get("properties", {}))
        unknown = sorted(set(error.instance) - set(allowed))
        where = _key_path(error)
        keys = ", ".join(repr(k) for k in unknown)
        return f"unknown key {keys} in '{where}' (allowed: {', '.join(allowed)})"
    return f"key '{_key_path(error)}': {error.message}"


def validate(instance: dict, schema_name: str, source: str) -> dict:
    """Validate ``instance`` in place against a schema, filling defaults.

    Parameters
    ----------
    instance : dict
        Parsed YAML content; modified in place (defaults added).
    schema_name : str
        Schema file in ``workflow/schemas``.
    source : str
        File name(s) the content came from, used in error messages.

    Returns
    -------
    dict
        The same ``instance``, with defaults.

    Raises
    ------
    ConfigError
        Listing every violation with its dotted key path.
    """
    schema = load_schema(schema_name)
    cls = _with_defaults(jsonschema.validators.validator_for(schema))
    validator = cls(schema)
    # Defaults first, so that nested defaults exist before dependent checks run.
    errors = sorted(validator.iter_errors(instance), key=lambda e: list(e.absolute_path))
    if errors:
        lines = "\n  ".join(_describe(e) for e in errors)
        raise ConfigError(f"{source}: invalid configuration:\n  {lines}")
    return instance


def validate_config(config: dict, source: str) -> dict:
    """Validate a workflow configuration (``config/*.yaml``) in place and return it."""
    return validate(config, "config.schema.yaml", source)


def load_config(path: str | Path) -> dict:
    """Read and validate a configuration file.

    Parameters
    ----------
    path : str or Path
        YAML configuration file.
    """
    path = Path(path)
    try:
        with path.open() as fh:
            data = yaml.safe_load(fh) or {}
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: not valid YAML: {exc}") from exc
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: top level must be a mapping")
    return validate_config(data, str(path))
