"""The contact parameters of the chute-cooler application.

The application runs one parameter set: explicit values from ``application.parameters`` or the
means of the identified parameters (the paper took the average of every parameter over the
valid sets), checked against the bounds of :mod:`demcal.core.parameters`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from demcal.core.config_values import SetupError
from demcal.core.parameters import CONTACT_PARAMETERS, out_of_bounds

__all__ = ["APPLICATION_PARAMETERS", "application_parameters"]

#: Contact parameters that the application takes from the identification (or the config).
APPLICATION_PARAMETERS = CONTACT_PARAMETERS

_SECTION = "application"


def application_parameters(
    section: Mapping[str, Any],
    identified: Mapping[str, Mapping[str, float]] | None,
    source: str = "identified parameters",
) -> dict[str, float]:
    """The contact parameter set of the application.

    Explicit values in ``application.parameters`` win; otherwise the means of the identified
    parameters are used (the paper took the average of every parameter over the valid sets).

    Parameters
    ----------
    section : mapping
        Configuration section ``application`` (key ``parameters``: a mapping or None;
        ``wall_friction``: a number or None).
    identified : mapping or None
        Per parameter a mapping with at least ``mean`` (the identification output), or None.
    source : str
        Name of the identified-parameter file, for error messages.

    Returns
    -------
    dict of str to float
        coefficientFriction (-), coefficientRollingFriction (-), coefficientRestitution (-),
        density (kg/m^3) and, if configured, wallFriction (-).

    Raises
    ------
    KeyError
        A parameter is missing (the message names the file or the configuration key).
    SetupError
        Neither explicit values nor identified parameters are given, or a value is out of range.
    """
    explicit = section.get("parameters")
    out: dict[str, float] = {}
    if explicit is not None:
        for name in APPLICATION_PARAMETERS:
            if name not in explicit:
                raise KeyError(f"configuration: missing key '{_SECTION}.parameters.{name}'")
            out[name] = float(explicit[name])
        where = f"'{_SECTION}.parameters'"
    elif identified is not None:
        for name in APPLICATION_PARAMETERS:
            if name not in identified:
                raise KeyError(f"{source}: missing parameter {name!r}")
            entry = identified[name]
            if not isinstance(entry, Mapping) or "mean" not in entry:
                raise KeyError(f"{source}: parameter {name!r} has no 'mean'")
            out[name] = float(entry["mean"])
        where = source
    else:
        raise SetupError(
            f"configuration: '{_SECTION}.parameters' is null and no identified parameters were "
            "given"
        )
    for name in APPLICATION_PARAMETERS:
        problem = out_of_bounds(name, out[name])
        if problem:
            raise SetupError(f"{where}: {problem}")
    wall = section.get("wall_friction")
    if wall is not None:
        wall = float(wall)
        problem = out_of_bounds("wallFriction", wall)
        if problem:
            raise SetupError(f"configuration: '{_SECTION}.wall_friction': {problem}")
        out["wallFriction"] = wall
    return out
