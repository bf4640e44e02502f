"""The parameters of a DEM case and the physical constants every stage shares.

Parameter names are the LIGGGHTS 3.8 keywords (``fix property/global``) and are used unchanged
from the configuration through the design table and the templates to the engine; wallFriction
is the particle-wall entry of the coefficientFriction matrix and dCylDp the cell size over the
particle diameter (the authors' name). Each name carries its unit, its short label for tables
and figures, and the interval of values that LIGGGHTS 3.8 accepts or the physics allows
(PHYSICS.md section 3). SI units throughout.

=============================  ==========================  ===================================
name                           values                      why
=============================  ==========================  ===================================
coefficientFriction            [0, inf)                    Coulomb coefficient
coefficientRollingFriction     [0, inf)                    EPSD2 coefficient
coefficientRestitution         (0.05, 1]                   LIGGGHTS rejects values outside
density                        (0, inf) kg/m^3
cohesionEnergyDensity          [0, inf) J/m^3              SJKR; 0 switches cohesion off
wallFriction                   [0, inf)                    particle-wall Coulomb coefficient
youngsModulus                  (0, inf) Pa                 >= 5e6 Pa unless ``soft_particles``
poissonsRatio                  (0, 0.5)                    inside LIGGGHTS's [0, 0.5] and the
                                                           bundled engine's (0, 0.5]
dCylDp                         (0, inf)                    cell over particle diameter
=============================  ==========================  ===================================
"""

from __future__ import annotations

import difflib
import math
import numbers
from dataclasses import dataclass

__all__ = [
    "CASE_PARAMETERS",
    "CONTACT_PARAMETERS",
    "ELASTIC_PARAMETERS",
    "GEOMETRY_PARAMETERS",
    "GRAVITY",
    "MAX_YOUNGS_MODULUS",
    "MIN_YOUNGS_MODULUS",
    "OPTIONAL_CONTACT_PARAMETERS",
    "PARAMETERS",
    "PARAMETER_LABELS",
    "TESTS",
    "Interval",
    "Parameter",
    "closest_parameter",
    "out_of_bounds",
    "unknown_parameter",
]

#: The virtual bulk tests, by the name used in case directories, configuration and datasets.
TESTS: tuple[str, ...] = ("shear_cell", "angle_of_repose")

#: Gravitational acceleration of every deck, set-up and readout, m/s^2 (acting along -z).
GRAVITY = 9.81

#: Smallest Young's modulus LIGGGHTS 3.8 accepts without ``soft_particles yes``, Pa.
MIN_YOUNGS_MODULUS = 5.0e6

#: Largest Young's modulus LIGGGHTS 3.8 accepts without ``hard_particles yes``, Pa. The decks
#: never set ``hard_particles``: calibration runs use softened particles.
MAX_YOUNGS_MODULUS = 1.0e9


@dataclass(frozen=True)
class Interval:
    """An interval of real numbers, each end open or closed.

    Attributes
    ----------
    low, high : float
        Ends (``math.inf`` for an unbounded end).
    low_closed, high_closed : bool
        Whether each end belongs to the interval.
    """

    low: float
    high: float
    low_closed: bool
    high_closed: bool

    def contains(self, x: float) -> bool:
        """Whether ``x`` lies in the interval (NaN never does)."""
        above = x >= self.low if self.low_closed else x > self.low
        below = x <= self.high if self.high_closed else x < self.high
        return above and below

    def __str__(self) -> str:
        left = "[" if self.low_closed else "("
        right = "]" if self.high_closed and not math.isinf(self.high) else ")"
        return f"{left}{_fmt(self.low)}, {_fmt(self.high)}{right}"


def _fmt(x: float) -> str:
    return "inf" if math.isinf(x) else f"{x:.12g}"


@dataclass(frozen=True)
class Parameter:
    """One parameter of a DEM case.

    Attributes
    ----------
    name : str
        LIGGGHTS keyword, also the configuration key and the design-table column.
    symbol : str
        Short symbol for tables and figures (e.g. ``mu_s``).
    unit : str
        SI unit, ``-`` for a dimensionless number.
    bounds : Interval
        Values LIGGGHTS 3.8 accepts or the physics allows.
    """

    name: str
    symbol: str
    unit: str
    bounds: Interval

    @property
    def label(self) -> str:
        """Symbol and unit, e.g. ``rho_p (kg/m^3)``."""
        return f"{self.symbol} ({self.unit})"


_INF = math.inf

#: Every parameter a case may carry, in the canonical order (deck headers, tables).
PARAMETERS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter("coefficientFriction", "mu_s", "-", Interval(0.0, _INF, True, False)),
        Parameter("coefficientRollingFriction", "mu_r", "-", Interval(0.0, _INF, True, False)),
        Parameter("coefficientRestitution", "COR", "-", Interval(0.05, 1.0, False, True)),
        Parameter("density", "rho_p", "kg/m^3", Interval(0.0, _INF, False, False)),
        Parameter("cohesionEnergyDensity", "k_coh", "J/m^3", Interval(0.0, _INF, True, False)),
        Parameter("wallFriction", "mu_w", "-", Interval(0.0, _INF, True, False)),
        Parameter("youngsModulus", "Y", "Pa", Interval(0.0, MAX_YOUNGS_MODULUS, False, True)),
        Parameter("poissonsRatio", "nu", "-", Interval(0.0, 0.5, False, False)),
        Parameter("dCylDp", "D/d_p", "-", Interval(0.0, _INF, False, False)),
    )
}

#: The four contact parameters the calibration identifies (paper: mu_s, mu_r, COR, rho_p).
CONTACT_PARAMETERS: tuple[str, ...] = (
    "coefficientFriction",
    "coefficientRollingFriction",
    "coefficientRestitution",
    "density",
)
#: Parameters the surrogates take the natural logarithm of (see
#: :mod:`demcal.surrogates.log_inputs`): a design that varies them must stay above 0.
LOG_SCALE_PARAMETERS: tuple[str, ...] = ("coefficientFriction",)
#: Contact parameters a case may add: SJKR cohesion and a separate particle-wall friction.
OPTIONAL_CONTACT_PARAMETERS: tuple[str, ...] = ("cohesionEnergyDensity", "wallFriction")
#: Elastic constants (from the ``material`` configuration unless a case column overrides them).
ELASTIC_PARAMETERS: tuple[str, ...] = ("youngsModulus", "poissonsRatio")
#: Size of the virtual test relative to the particles.
GEOMETRY_PARAMETERS: tuple[str, ...] = ("dCylDp",)
#: Every case column the decks read, in the canonical order.
CASE_PARAMETERS: tuple[str, ...] = tuple(PARAMETERS)

#: Short labels of the identified contact parameters in tables and figures.
PARAMETER_LABELS: dict[str, str] = {name: PARAMETERS[name].label for name in CONTACT_PARAMETERS}


def closest_parameter(name: str) -> str | None:
    """The known parameter name closest to a misspelt ``name``, or None when none is close."""
    by_lower = {p.lower(): p for p in PARAMETERS}
    if name.lower() in by_lower:
        return by_lower[name.lower()]
    match = difflib.get_close_matches(name.lower(), list(by_lower), n=1, cutoff=0.6)
    return by_lower[match[0]] if match else None


def unknown_parameter(name: str) -> str | None:
    """Why ``name`` is not a case parameter (with a suggestion), or None when it is one."""
    if name in PARAMETERS:
        return None
    guess = closest_parameter(name)
    if guess is not None:
        return f"unknown contact parameter (did you mean {guess}?)"
    return f"unknown contact parameter (known: {', '.join(PARAMETERS)})"


def out_of_bounds(name: str, value: object, bounds: Interval | None = None) -> str | None:
    """Why ``value`` is not a valid value of parameter ``name``, or None when it is.

    Parameters
    ----------
    name : str
        Parameter name.
    value : object
        The value to check.
    bounds : Interval, optional
        Bounds to use instead of the parameter's own (e.g. a stricter minimum).

    Returns
    -------
    str or None
        E.g. ``"coefficientRestitution = 1.5 is outside (0.05, 1]"``.

    Raises
    ------
    KeyError
        ``name`` is not a known parameter and no ``bounds`` are given.
    """
    if bounds is None:
        bounds = PARAMETERS[name].bounds
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return f"{name} = {value!r} is not a number"
    x = float(value)
    if math.isnan(x):
        return f"{name} = nan is not a number"
    if not bounds.contains(x):
        return f"{name} = {_fmt(x)} is outside {bounds}"
    return None
