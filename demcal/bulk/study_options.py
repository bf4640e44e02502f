"""Command-line options shared by the study scripts: configuration and parameter sets.

The engine comparison, the convergence study and the cycle study each render decks for a few
parameter sets from one configuration. They read the same options, parsed here, so a set or an
override is spelt alike in all of them and refused with the same message before any run:

* ``--config PATH`` and ``--set SECTION.KEY=VALUE`` (repeatable, validated with the file);
* ``--sets NAME ...``: reference sets of :func:`demcal.bulk.engine_comparison.parameter_sets`;
* ``--extra-set NAME=key:value,...`` (repeatable): a set given in full, e.g. where a
  calibration landed.
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from demcal.bulk.engine_comparison import select_parameter_sets
from demcal.core.config import ConfigError, load_config, with_overrides
from demcal.core.parameters import (
    CONTACT_PARAMETERS,
    OPTIONAL_CONTACT_PARAMETERS,
    out_of_bounds,
    unknown_parameter,
)

__all__ = [
    "add_parameter_sets",
    "add_study_options",
    "parse_parameter_set",
    "study_sets",
    "study_settings",
]


def add_study_options(
    parser: argparse.ArgumentParser,
    *,
    config: str,
    sets: Sequence[str],
    extra_set_help: str = "a further parameter set, e.g. where a calibration landed",
) -> None:
    """Add ``--config``, ``--set``, ``--sets`` and ``--extra-set`` to ``parser``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The script's parser; the options land in ``config``, ``overrides``, ``sets`` and
        ``extra_set``.
    config : str
        Default configuration file.
    sets : sequence of str
        Default reference sets.
    extra_set_help : str
        What an extra set is for in this script (the parameter list is appended).
    """
    parser.add_argument("--config", default=config, help="configuration YAML")
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="override a configuration key for every deck (VALUE read as YAML); repeatable",
    )
    parser.add_argument(
        "--sets",
        nargs="*",
        default=list(sets),
        help="reference parameter sets (low, middle, high, interlocking, cohesion; none with "
        "--sets alone: only the --extra-set ones)",
    )
    parser.add_argument(
        "--extra-set",
        action="append",
        default=[],
        metavar="NAME=key:value,...",
        help=f"{extra_set_help}, run after --sets (every contact parameter: "
        f"{', '.join(CONTACT_PARAMETERS)}; optionally "
        f"{', '.join(OPTIONAL_CONTACT_PARAMETERS)}); repeatable",
    )


def study_settings(args: argparse.Namespace) -> dict[str, Any]:
    """The configuration of ``--config`` with the ``--set`` overrides applied.

    Raises
    ------
    SystemExit
        The file cannot be read, or it or an override is refused; the message names the file,
        key or override.
    """
    try:
        return with_overrides(load_config(Path(args.config)), args.overrides, args.config)
    except ConfigError as exc:
        raise SystemExit(str(exc)) from None
    except OSError as exc:
        raise SystemExit(f"--config {args.config}: {exc.strerror}") from None


def study_sets(
    args: argparse.Namespace, settings: Mapping[str, Any], profile: str
) -> dict[str, dict[str, float]]:
    """The ``--sets`` of the configuration's profile followed by the ``--extra-set`` ones.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed options of :func:`add_study_options`.
    settings : mapping
        The configuration; its ``profile`` picks the reference sets.
    profile : str
        Profile assumed when the configuration names none.

    Returns
    -------
    dict
        Set name -> contact parameters, in the order given.

    Raises
    ------
    SystemExit
        An unknown set name, an extra set that does not parse or repeats a name, or no set at
        all; the message names the option.
    """
    try:
        sets = select_parameter_sets(args.sets, str(settings.get("profile", profile)))
    except ValueError as exc:
        raise SystemExit(f"--sets: {exc}") from None
    try:
        sets = add_parameter_sets(sets, args.extra_set)
    except ValueError as exc:
        raise SystemExit(f"--extra-set: {exc}") from None
    if not sets:
        raise SystemExit("no parameter sets: name some with --sets or add one with --extra-set")
    return sets


def parse_parameter_set(text: str) -> tuple[str, dict[str, float]]:
    """A named parameter set from the command line, e.g. one where a calibration landed.

    Parameters
    ----------
    text : str
        ``NAME=key:value,key:value,...`` with every contact parameter (``coefficientFriction``,
        ``coefficientRollingFriction``, ``coefficientRestitution``, ``density`` in kg/m^3) and
        optionally ``cohesionEnergyDensity`` (J/m^3) or ``wallFriction``.

    Returns
    -------
    tuple of (str, dict)
        The set's name and its parameters.

    Raises
    ------
    ValueError
        Malformed text, an unknown or repeated parameter, a value that is not a number or
        outside its bounds, or a contact parameter missing; the message names the culprit.
    """
    name, sep, body = text.partition("=")
    name = name.strip()
    if not sep or not name or "/" in name:
        raise ValueError(f"parameter set {text!r}: expected NAME=key:value,... (NAME without '/')")
    params: dict[str, float] = {}
    for item in body.split(","):
        key, colon, raw = (part.strip() for part in item.partition(":"))
        if not colon:
            raise ValueError(f"parameter set {name}: {item.strip()!r} is not key:value")
        why = unknown_parameter(key)
        if why is None and key not in CONTACT_PARAMETERS + OPTIONAL_CONTACT_PARAMETERS:
            why = "not a contact parameter"
        if why is not None:
            raise ValueError(f"parameter set {name}: {key}: {why}")
        if key in params:
            raise ValueError(f"parameter set {name}: {key} given twice")
        try:
            value = float(raw)
        except ValueError:
            raise ValueError(f"parameter set {name}: {key} = {raw!r} is not a number") from None
        problem = out_of_bounds(key, value)
        if problem is not None:
            raise ValueError(f"parameter set {name}: {problem}")
        params[key] = value
    missing = [key for key in CONTACT_PARAMETERS if key not in params]
    if missing:
        raise ValueError(f"parameter set {name}: missing {', '.join(missing)}")
    return name, params


def add_parameter_sets(
    sets: Mapping[str, Mapping[str, float]], texts: Sequence[str]
) -> dict[str, dict[str, float]]:
    """``sets`` with the sets of :func:`parse_parameter_set` from ``texts`` added after them.

    Raises
    ------
    ValueError
        A text that does not parse (the message names the culprit), or a name already taken.
    """
    merged = {name: dict(params) for name, params in sets.items()}
    for text in texts:
        name, params = parse_parameter_set(text)
        if name in merged:
            raise ValueError(f"a set named {name} is already in the study")
        merged[name] = params
    return merged
