"""Reading set-up values from a validated configuration section with errors that name the key.

The schema already checks types and ranges; these checks guard the derived set-up code when it
is called directly (tests, scripts) and name the dotted key of any bad value.
"""

import math
from collections.abc import Mapping
from typing import Any


class SetupError(ValueError):
    """A configuration that makes a virtual test impossible to set up (names the key)."""


def required(section: Mapping[str, Any], key: str, where: str) -> Any:
    """``section[key]``; a missing key raises ``KeyError`` naming ``where.key``."""
    if key not in section:
        raise KeyError(f"configuration: missing key '{where}.{key}'")
    return section[key]


def positive_value(value: Any, where: str) -> float:
    """``value`` as a finite float > 0, else ``SetupError`` naming ``where``."""
    x = float(value)
    if not (math.isfinite(x) and x > 0.0):
        raise SetupError(f"configuration: '{where}' must be a positive number, got {value!r}")
    return x


def non_negative_value(value: Any, where: str) -> float:
    """``value`` as a finite float >= 0, else ``SetupError`` naming ``where``."""
    x = float(value)
    if not (math.isfinite(x) and x >= 0.0):
        raise SetupError(f"configuration: '{where}' must be >= 0, got {value!r}")
    return x


def fraction_value(value: Any, where: str, low: float = 0.0, high: float = 1.0) -> float:
    """``value`` as a float in (low, high], else ``SetupError`` naming ``where``."""
    x = float(value)
    if not (math.isfinite(x) and low < x <= high):
        raise SetupError(f"configuration: '{where}' must lie in ({low:g}, {high:g}], got {value!r}")
    return x


def positive(section: Mapping[str, Any], key: str, where: str) -> float:
    """``section[key]`` as a finite float > 0."""
    return positive_value(required(section, key, where), f"{where}.{key}")


def fraction(section: Mapping[str, Any], key: str, where: str) -> float:
    """``section[key]`` as a float in (0, 1]."""
    return fraction_value(required(section, key, where), f"{where}.{key}")


def in_range(section: Mapping[str, Any], key: str, lo: float, hi: float, where: str) -> float:
    """``section[key]`` as a float in [lo, hi]."""
    x = float(required(section, key, where))
    if not (math.isfinite(x) and lo <= x <= hi):
        raise SetupError(f"configuration: '{where}.{key}' must lie in [{lo}, {hi}], got {x!r}")
    return x


def count(section: Mapping[str, Any], key: str, minimum: int, where: str) -> int:
    """``section[key]`` as an int >= minimum."""
    x = int(required(section, key, where))
    if x < minimum:
        raise SetupError(f"configuration: '{where}.{key}' must be >= {minimum}, got {x}")
    return x
