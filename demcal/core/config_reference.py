"""Markdown reference of the workflow configuration, generated from its JSON schema.

The schema ``workflow/schemas/config.schema.yaml`` (JSON Schema draft 2020-12) is the one place
where a configuration key, its type, default, allowed values and meaning are written down. This
module renders it to ``docs/configuration.md`` so that the reference cannot drift from the
schema (``tests/unit/test_docs.py`` fails when the two differ)::

    python -m demcal.core.config_reference > docs/configuration.md
    python -m demcal.core.config_reference --output docs/configuration.md   # what `make docs` runs

The page has one section per top-level key, each with a table of key path, type, default,
allowed values or range, and description. Items of an array of objects (the discrepancy
candidates) appear as ``key[].field``.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from demcal.core.config import load_schema

__all__ = ["SCHEMA_NAME", "KeyEntry", "iter_keys", "key_paths", "main", "render_markdown"]

SCHEMA_NAME = "config.schema.yaml"

# Defaults whose JSON text is longer than this are shown as a YAML block below the table.
_INLINE_DEFAULT_CHARS = 48

_PREAMBLE = """\
<!-- Generated from workflow/schemas/config.schema.yaml by
     `python -m demcal.core.config_reference`; edit the schema, then run `make docs`. -->

# Configuration reference

{description}

`config/config.yaml` is the default (quick) study, `config/tiny.yaml` the one the tests use and
`config/paper.yaml` the paper scale. A key that no configuration file sets takes the default
below. Note that Snakemake merges a file given with `--configfile` over `config/config.yaml`
(the workflow's `configfile:`), so a key that the file leaves out keeps the value of
`config/config.yaml`, not the schema default. The configuration is validated when the workflow
starts: an unknown key or a value out of range stops the run before any job executes, with a
message that names the file and the key, for example

```
config/config.yaml: invalid configuration:
  key 'engine.threads': 0 is less than the minimum of 1
```

Checks across keys follow, at the same point: contact-parameter names (with a suggestion for a
misspelt one) and their physical bounds; a varied sliding friction that reaches 0 (the
surrogates take its logarithm); shear-cell keys that only work together; and a varied
`coefficientRollingFriction` with `material.rolling_friction: false` (the contact model ignores
it, so its runs would be spent on an input without effect).

Run another configuration with
`snakemake --cores all --force-use-threads --configfile config/tiny.yaml`.

Parameter names follow the LIGGGHTS keywords (`coefficientFriction`,
`coefficientRollingFriction`, `coefficientRestitution`, `density`, `youngsModulus`, ...) from
the configuration through the templates to the engine. In the tables, a range such as `[0, 1)`
includes 0 and excludes 1; `key[].field` is a field of every item of the list `key`.

This page is generated from `workflow/schemas/config.schema.yaml` (JSON Schema draft 2020-12);
do not edit it by hand. Regenerate it after a schema change with `make docs` (or
`python -m demcal.core.config_reference > docs/configuration.md`).

Sections: {contents}
"""


@dataclass(frozen=True)
class KeyEntry:
    """One configuration key of the schema.

    Attributes
    ----------
    path : str
        Dotted key path, e.g. ``"engine.threads"``; ``"[]"`` marks the items of a list.
    schema : Mapping[str, Any]
        The key's sub-schema.
    required : bool
        The key has no default and must be given (fields of list items).
    """

    path: str
    schema: Mapping[str, Any]
    required: bool = False


def _types(schema: Mapping[str, Any]) -> list[str]:
    kind = schema.get("type", [])
    return [kind] if isinstance(kind, str) else list(kind)


def iter_keys(schema: Mapping[str, Any], prefix: str = "") -> Iterator[KeyEntry]:
    """Walk every configuration key of a schema in schema order, depth first.

    Parameters
    ----------
    schema : Mapping[str, Any]
        An object schema (the whole configuration schema or a sub-schema).
    prefix : str
        Key path of ``schema`` followed by a dot, or ``""`` at the top level.

    Yields
    ------
    KeyEntry
        Every named property, then its own properties (and those of its list items).
    """
    required = set(schema.get("required", []))
    for name, sub in schema.get("properties", {}).items():
        path = f"{prefix}{name}"
        yield KeyEntry(path, sub, name in required and "default" not in sub)
        yield from iter_keys(sub, f"{path}.")
        items = sub.get("items")
        if isinstance(items, Mapping) and "properties" in items:
            yield from iter_keys(items, f"{path}[].")


def key_paths(schema: Mapping[str, Any] | None = None) -> list[str]:
    """Every key path of the configuration schema, in schema order.

    Parameters
    ----------
    schema : Mapping[str, Any], optional
        Schema to walk; the workflow's configuration schema when omitted.
    """
    schema = load_schema(SCHEMA_NAME) if schema is None else schema
    return [entry.path for entry in iter_keys(schema)]


def _number(value: Any) -> str:
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return str(value)


def _bounds(schema: Mapping[str, Any]) -> str:
    low = high = ""
    if "minimum" in schema:
        low = f"[{_number(schema['minimum'])}"
    elif "exclusiveMinimum" in schema:
        low = f"({_number(schema['exclusiveMinimum'])}"
    if "maximum" in schema:
        high = f"{_number(schema['maximum'])}]"
    elif "exclusiveMaximum" in schema:
        high = f"{_number(schema['exclusiveMaximum'])})"
    if low and high:
        return f"`{low}, {high}`"
    if low:
        sign = ">=" if low[0] == "[" else ">"
        return f"{sign} {low[1:]}"
    if high:
        sign = "<=" if high[-1] == "]" else "<"
        return f"{sign} {high[:-1]}"
    return ""


def _allowed(schema: Mapping[str, Any]) -> str:
    parts = []
    if "enum" in schema:
        parts.append(", ".join(f"`{v}`" for v in schema["enum"]))
    if bounds := _bounds(schema):
        parts.append(bounds)
    if "pattern" in schema:
        parts.append(f"matches `{schema['pattern']}`")
    items = schema.get("items")
    if isinstance(items, Mapping) and "properties" not in items:
        if item_allowed := _allowed(items):
            parts.append(f"each {item_allowed}")
    extra = schema.get("additionalProperties")
    if isinstance(extra, Mapping) and extra:
        if value_allowed := _allowed(extra):
            parts.append(f"each value {value_allowed}")
    return "; ".join(parts)


def _count(schema: Mapping[str, Any]) -> str:
    low, high = schema.get("minItems"), schema.get("maxItems")
    if low is not None and low == high:
        return f"{low} items"
    if low is not None and high is not None:
        return f"{low}-{high} items"
    if low is not None:
        return f"at least {low} item{'s' if low != 1 else ''}"
    if high is not None:
        return f"at most {high} items"
    return ""


def _type(schema: Mapping[str, Any]) -> str:
    names = []
    for kind in _types(schema):
        if kind == "array":
            items = schema.get("items", {})
            inner = "object" if "properties" in items else _type(items) or "value"
            count = _count(schema)
            names.append(f"list of {inner}" + (f" ({count})" if count else ""))
        elif kind == "object" and isinstance(schema.get("additionalProperties"), Mapping):
            value = _type(schema["additionalProperties"]) or "value"
            names.append(f"mapping: name to {value}")
        else:
            names.append(kind)
    return " or ".join(names)


def _value(value: Any) -> str:
    """A default as written in YAML flow style: numbers as given, large round floats as 1e7."""
    if isinstance(value, str):
        return value
    if isinstance(value, float) and value.is_integer() and abs(value) >= 1e5:
        return re.sub(r"e\+?0*", "e", f"{value:g}")
    if isinstance(value, list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    return json.dumps(value, ensure_ascii=False, separators=(", ", ": "))


def _default(entry: KeyEntry) -> tuple[str, Any]:
    """Table text of a key's default, and the value to show below the table if it is long."""
    schema = entry.schema
    if entry.required:
        return "required", None
    if "default" not in schema:
        return "", None
    value = schema["default"]
    if "properties" in schema and value == {}:
        return "", None  # an object whose keys have their own defaults
    text = _value(value)
    if len(text) > _INLINE_DEFAULT_CHARS:
        return "see below", value
    return f"`{text}`", None


def _cell(text: str) -> str:
    return re.sub(r"\s+", " ", text).strip().replace("|", "\\|")


def _section(entry: KeyEntry) -> list[str]:
    sub = entry.schema
    lines = [f"## `{entry.path}`", ""]
    if "properties" in sub:
        # An object: its description heads the section, its keys fill the table.
        lines += [_cell(sub.get("description", "")), ""]
        rows = list(iter_keys(sub, f"{entry.path}."))
    else:
        rows = [entry]
    items = sub.get("items")
    if isinstance(items, Mapping) and "properties" in items:
        rows.extend(iter_keys(items, f"{entry.path}[]."))
    lines += [
        "| key | type | default | allowed | description |",
        "| --- | --- | --- | --- | --- |",
    ]
    long_defaults = []
    for row in rows:
        default, value = _default(row)
        if value is not None:
            long_defaults.append((row.path, value))
        description = row.schema.get("description", "")
        lines.append(
            f"| `{row.path}` | {_cell(_type(row.schema))} | {default} "
            f"| {_cell(_allowed(row.schema))} | {_cell(description)} |"
        )
    for path, value in long_defaults:
        dumped = yaml.safe_dump(value, sort_keys=False, default_flow_style=None, width=96)
        lines += ["", f"Default of `{path}`:", "", "```yaml", dumped.rstrip(), "```"]
    lines.append("")
    return lines


def _anchor(path: str) -> str:
    return re.sub(r"[^a-z0-9_ -]", "", path.lower()).replace(" ", "-")


def render_markdown(schema: Mapping[str, Any] | None = None) -> str:
    """Render the configuration schema as the Markdown page ``docs/configuration.md``.

    Parameters
    ----------
    schema : Mapping[str, Any], optional
        Schema to render; the workflow's configuration schema when omitted.

    Returns
    -------
    str
        The page, ending in a single newline; the same schema always gives the same text.
    """
    schema = load_schema(SCHEMA_NAME) if schema is None else schema
    top = [KeyEntry(name, sub) for name, sub in schema.get("properties", {}).items()]
    contents = ", ".join(f"[`{e.path}`](#{_anchor(e.path)})" for e in top)
    text = _PREAMBLE.format(description=_cell(schema.get("description", "")), contents=contents)
    lines = [text]
    for entry in top:
        lines += _section(entry)
    return "\n".join(lines).rstrip("\n") + "\n"


def main(argv: list[str] | None = None) -> int:
    """Command line: write the configuration reference to standard output or a file.

    Parameters
    ----------
    argv : list of str, optional
        Arguments; ``sys.argv[1:]`` when omitted. ``--output PATH`` writes the page to PATH
        (only once it has been rendered completely) instead of standard output.
    """
    parser = argparse.ArgumentParser(
        prog="python -m demcal.core.config_reference",
        description="Render workflow/schemas/config.schema.yaml as Markdown.",
    )
    parser.add_argument("--output", "-o", type=Path, help="write to this file, not stdout")
    args = parser.parse_args(argv)
    text = render_markdown()
    if args.output is None:
        sys.stdout.write(text)
    else:
        args.output.parent.mkdir(parents=True, exist_ok=True)
        args.output.write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
