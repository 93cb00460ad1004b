"""Unit conversions at the file boundary: people write metres and degrees, the core uses radians."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from robomax_py._typing import FloatArray


def deg_to_rad(value_deg: float) -> float:
    return math.radians(value_deg)


def rad_to_deg(value_rad: float) -> float:
    return math.degrees(value_rad)


def degs_to_rads(values_deg: Sequence[float] | FloatArray) -> FloatArray:
    out: FloatArray = np.radians(np.asarray(values_deg, dtype=float))
    return out


def rads_to_degs(values_rad: Sequence[float] | FloatArray) -> FloatArray:
    out: FloatArray = np.degrees(np.asarray(values_rad, dtype=float))
    return out


def m_to_mm(value_m: float) -> float:
    return value_m * 1000.0


def mm_to_m(value_mm: float) -> float:
    return value_mm / 1000.0
