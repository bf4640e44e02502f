"""Loading and validating workflow configuration against the JSON schema.

The schema (``workflow/schemas/config.schema.yaml``, JSON Schema draft 2020-12) gives every key
a description and a default; validation fills the defaults in and reports every problem with the
dotted key path, so a typo or an out-of-range value stops the workflow before anything runs.

Contact parameters are keys of free-form mappings in the schema (``design.ranges`` and others),
so their names and values are checked afterwards against :mod:`demcal.core.parameters`: a
misspelt name (``design.ranges.coefficientFrction``) or a value outside what LIGGGHTS accepts
(a restitution of 1.5) is a configuration error that names the key.
"""

from __future__ import annotations

import copy
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import jsonschema
import yaml

from demcal.core.parameters import LOG_SCALE_PARAMETERS, out_of_bounds, unknown_parameter

SCHEMA_DIR = Path(__file__).resolve().parents[2] / "workflow" / "schemas"

#: Keys of the ``design`` section that each kind of design reads (the others are ignored).
DESIGN_KEYS_BY_KIND: dict[str, tuple[str, ...]] = {
    "factorial": ("kind", "levels", "fixed"),
    "random": ("kind", "n", "seed", "ranges", "choices", "fixed"),
    "lhs": ("kind", "n", "seed", "ranges", "choices", "fixed"),
    "sobol": ("kind", "n", "seed", "ranges", "choices", "fixed"),
}


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


def _values_problems(where: str, name: str, values: Any) -> list[str]:
    """Problems of the values of parameter ``name`` given at key path ``where``."""
    reason = unknown_parameter(name)
    if reason is not None:
        return [f"{where}: {reason}"]
    if not isinstance(values, list):
        problem = out_of_bounds(name, values)
        return [f"{where}: {problem}"] if problem else []
    problems = []
    for i, value in enumerate(values):
        problem = out_of_bounds(name, value)
        if problem:
            problems.append(f"{where}[{i}]: {problem}")
    return problems


def _candidate_problems(i: int, candidate: Mapping[str, Any]) -> list[str]:
    """Problems of ``discrepancy.candidates[i]``: its parameter, range, probes and off value.

    A candidate with a ``config_key`` names a new surrogate input, not a case column, and is
    not checked.
    """
    if candidate.get("config_key") is not None:
        return []
    where = f"discrepancy.candidates[{i}]"
    name = candidate["parameter"]
    reason = unknown_parameter(name)
    if reason is not None:
        return [f"{where}.parameter: {name!r}: {reason}"]
    problems = _values_problems(f"{where}.range", name, candidate["range"])
    problems += _values_problems(f"{where}.probe_levels", name, candidate["probe_levels"])
    off = candidate["off_value"]
    if isinstance(off, str):
        reason = unknown_parameter(off)
        if reason is not None:
            problems.append(f"{where}.off_value: {off!r}: {reason}")
    else:
        problems += _values_problems(f"{where}.off_value", name, off)
    return problems


def parameter_problems(config: Mapping[str, Any]) -> list[str]:
    """Every misspelt contact-parameter name and out-of-bounds value of a configuration.

    Checks the design (``ranges``, ``levels``, ``choices``, ``fixed``), the material's elastic
    constants, the screening axes (low and high), the discrepancy candidates and the
    application's parameters and wall friction.

    Parameters
    ----------
    config : mapping
        A configuration that passed the schema (with defaults filled in).

    Returns
    -------
    list of str
        One line per problem, starting with the dotted key path, e.g.
        ``design.ranges.coefficientFrction: unknown contact parameter (did you mean
        coefficientFriction?)``.
    """
    problems: list[str] = []
    design = config.get("design", {})
    for key in ("ranges", "levels", "choices", "fixed"):
        for name, values in design.get(key, {}).items():
            problems += _values_problems(f"design.{key}.{name}", name, values)
    material = config.get("material", {})
    for name in ("youngsModulus", "poissonsRatio"):
        if name in material:
            problems += _values_problems(f"material.{name}", name, material[name])
    for name, axis in config.get("screening", {}).get("axes", {}).items():
        problems += _values_problems(f"screening.axes.{name}", name, list(axis[:2]))
    for i, candidate in enumerate(config.get("discrepancy", {}).get("candidates", [])):
        problems += _candidate_problems(i, candidate)
    application = config.get("application", {})
    for name, value in (application.get("parameters") or {}).items():
        problems += _values_problems(f"application.parameters.{name}", name, value)
    if application.get("wall_friction") is not None:
        problems += _values_problems(
            "application.wall_friction", "wallFriction", application["wall_friction"]
        )
    return problems


def _log_scale_problems(config: Mapping[str, Any]) -> list[str]:
    """Design values of a log-scale parameter that are not above 0.

    The surrogates take the logarithm of these inputs (``LOG_SCALE_PARAMETERS``); a design or
    screening axis reaching 0 would stop the study at training, after its DEM runs.
    """
    design = config.get("design", {})
    places = [(f"design.{key}", design.get(key, {})) for key in ("ranges", "levels", "choices")]
    places.append(("screening.axes", config.get("screening", {}).get("axes", {})))
    problems = []
    for where, section in places:
        for name in LOG_SCALE_PARAMETERS:
            values = section.get(name)
            if values is None:
                continue
            values = values[:2] if where == "screening.axes" else values
            low = min(values) if isinstance(values, list) else values
            if isinstance(low, int | float) and low <= 0.0:
                problems.append(
                    f"{where}.{name}: must stay above 0, got {low:g} (the surrogates take the "
                    "logarithm of this input; start the range at e.g. 0.05)"
                )
    return problems


def _shear_cell_problems(config: Mapping[str, Any]) -> list[str]:
    """Combinations of ``shear_cell`` keys that the schema cannot express."""
    cell = config.get("shear_cell", {})
    problems = []
    if cell.get("cycles") == "continue" and cell.get("geometry") != "ring":
        # A split cell's lower part would move one cycle's travel further per cycle.
        problems.append(
            "shear_cell.cycles: 'continue' needs shear_cell.geometry 'ring', got "
            f"{cell.get('geometry')!r} (a split cell cannot keep shearing in one direction)"
        )
    if cell.get("bulk_density") == "interior" and cell.get("geometry") != "ring":
        # The split cell's lower part moves sideways under the bed: no region stays inside.
        problems.append(
            "shear_cell.bulk_density: 'interior' needs shear_cell.geometry 'ring', got "
            f"{cell.get('geometry')!r}"
        )
    return problems


def _switched_off_problems(config: Mapping[str, Any]) -> list[str]:
    """Design parameters that are varied although the contact model ignores them.

    With ``material.rolling_friction: false`` the decks write no rolling-resistance model, so a
    varied ``coefficientRollingFriction`` would spend DEM runs on an input without effect and
    leave it unidentifiable in the screening.
    """
    if config.get("material", {}).get("rolling_friction", True):
        return []
    design = config.get("design", {})
    name = "coefficientRollingFriction"
    read = DESIGN_KEYS_BY_KIND[design["kind"]]
    problems = []
    for key in (k for k in ("levels", "ranges", "choices") if k in read):
        values = design.get(key, {}).get(name)
        if isinstance(values, list) and len(set(values)) > 1:
            problems.append(
                f"design.{key}.{name}: varied, but material.rolling_friction is false (the "
                f"contact model ignores it); hold it in design.fixed instead or switch "
                f"rolling friction on"
            )
    return problems


def validate_config(config: dict, source: str) -> dict:
    """Validate a workflow configuration (``config/*.yaml``) in place and return it.

    The schema first (filling defaults), then the contact-parameter names and values
    (:func:`parameter_problems`), the shear-cell keys that only work together and design
    parameters the contact model switches off.

    Raises
    ------
    ConfigError
        Listing every violation with its dotted key path.
    """
    validate(config, "config.schema.yaml", source)
    problems = parameter_problems(config) + _shear_cell_problems(config)
    problems += _log_scale_problems(config) + _switched_off_problems(config)
    if problems:
        lines = "\n  ".join(problems)
        raise ConfigError(f"{source}: invalid configuration:\n  {lines}")
    return config


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


def with_overrides(config: Mapping[str, Any], texts: list[str], source: str) -> dict:
    """A validated configuration with ``SECTION.KEY=VALUE`` overrides applied.

    Parameters
    ----------
    config : mapping
        A validated configuration (left unchanged).
    texts : list of str
        Overrides such as ``shear_cell.contact_snapshots=25``; the value is read as YAML.
    source : str
        Where ``config`` came from, for the error message.

    Raises
    ------
    ConfigError
        An override not of the form ``SECTION.KEY=VALUE``, or a result the schema refuses (a
        misspelt key, a wrong value), naming the overrides.
    """
    cfg = copy.deepcopy(dict(config))
    for text in texts:
        key, sep, value = text.partition("=")
        section, dot, name = key.partition(".")
        if not (sep and dot and name):
            raise ConfigError(f"override {text!r}: expected SECTION.KEY=VALUE")
        cfg.setdefault(section, {})[name] = yaml.safe_load(value)
    return validate_config(cfg, f"{source} with --set {' '.join(texts)}")
