"""Input checks shared by the wrappers: clear ``ValueError``/``TypeError`` before Rust sees a value."""

from __future__ import annotations

import math
import numbers
from typing import Any


def real(name: str, value: Any) -> float:
    """``value`` as a finite float; the error names ``name``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__} {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be a finite number, got {v}")
    return v


def positive(name: str, value: Any) -> float:
    """``value`` as a finite float > 0."""
    v = real(name, value)
    if v <= 0.0:
        raise ValueError(f"{name} must be > 0, got {v}")
    return v


def nonneg(name: str, value: Any) -> float:
    """``value`` as a finite float >= 0."""
    v = real(name, value)
    if v < 0.0:
        raise ValueError(f"{name} must be >= 0, got {v}")
    return v


def count(name: str, value: Any, minimum: int = 0) -> int:
    """``value`` as an int >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__} {value!r}")
    v = int(value)
    if v < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {v}")
    return v
