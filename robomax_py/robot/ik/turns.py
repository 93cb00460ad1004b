"""Joint-limit filtering and turn variants (q + 2 pi k) of IK solutions, as a fixed-shape expansion.

IK solvers return revolute angles wrapped into (-pi, pi]. A joint whose limits reach beyond that
interval (KUKA A4/A6 at +-350 deg, UR joints at +-360 deg, or a range such as [-10, 350] deg) can hold
the same solution at q + 2 pi k as well. `turn_shifts` lists, once per robot, every combination of
such shifts that can land inside the limits; `expand` applies all of them to every solution and
marks which results are inside the limits.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import BoolArray, FloatArray, IntArray

TWO_PI = 2.0 * np.pi
# A value this far (rad or m) outside a limit still counts as inside and is clamped onto the limit:
# it absorbs round-off of solutions that sit exactly on a limit.
LIMIT_SLACK = 1e-12
_MIN_OVERLAP = 1e-9


def wrap_to_pi(q: FloatArray) -> FloatArray:
    """Angles (any shape, rad) moved by multiples of 2 pi into (-pi, pi]."""
    out = np.pi - np.mod(np.pi - np.asarray(q, dtype=float), TWO_PI)
    # mod may round up to exactly 2 pi for arguments a hair below a multiple of it.
    return np.where(out <= -np.pi, out + TWO_PI, out)


@dataclass(frozen=True, slots=True, eq=False)
class TurnVariants:
    """Every turn variant a robot's limits allow.

    shifts : (V, n) float, rad
        Row v is added to a wrapped solution to make variant v. Per joint the shifts are ordered
        0, -2 pi, +2 pi, -4 pi, +4 pi, ... (those that apply) and rows enumerate their combinations in
        C order (the last joint varies fastest); so row 0 is all zeros whenever every joint's range
        overlaps (-pi, pi].
    joint_shifts : per joint, (K_j,) float: the shifts that joint takes, in the order above.
    index : (V, n) int
        shifts[v, j] == joint_shifts[j][index[v, j]].
    lower, upper : (n,) float
        The joint limits the variants were computed for, rad or m.
    """

    shifts: FloatArray
    joint_shifts: tuple[FloatArray, ...]
    index: IntArray
    lower: FloatArray
    upper: FloatArray

    @property
    def count(self) -> int:
        """V, the number of variants per IK branch."""
        return int(self.shifts.shape[0])


def turn_shifts(lower: FloatArray, upper: FloatArray, revolute: BoolArray | None = None) -> TurnVariants:
    """The turn variants that can fall inside [lower, upper].

    Parameters
    ----------
    lower, upper : (n,) float
        Joint limits, rad (m for prismatic joints).
    revolute : (n,) bool, optional
        Which joints are revolute; prismatic joints never get variants. Default: all revolute.

    Returns
    -------
    TurnVariants
        For joint j the shifts are the 2 pi k whose interval (-pi, pi] + 2 pi k meets [lower_j, upper_j].
    """
    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    rev = np.ones(lower.shape, dtype=bool) if revolute is None else np.asarray(revolute, dtype=bool)
    per_joint: list[list[float]] = []
    for lo, hi, is_rev in zip(lower, upper, rev, strict=True):
        if not is_rev or not (np.isfinite(lo) and np.isfinite(hi)):
            per_joint.append([0.0])                   # prismatic, or no finite range to fill
            continue
        # k such that (-pi, pi] + 2 pi k overlaps [lo, hi] by more than a sliver: a range of exactly
        # [-pi, pi] must not yield -pi and pi as two variants of one solution.
        ks = [
            k
            for k in range(int(np.floor((lo + np.pi) / TWO_PI)) - 1, int(np.ceil((hi - np.pi) / TWO_PI)) + 2)
            if min(hi, np.pi + TWO_PI * k) - max(lo, -np.pi + TWO_PI * k) > _MIN_OVERLAP
        ]
        per_joint.append([TWO_PI * k for k in sorted(ks or [0], key=lambda k: (abs(k), k))])
    index = np.array(list(itertools.product(*[range(len(p)) for p in per_joint])), dtype=np.int64)
    index = index.reshape(-1, len(per_joint))
    joint_shifts = tuple(np.array(p, dtype=float) for p in per_joint)
    shifts = np.stack([joint_shifts[j][index[:, j]] for j in range(len(per_joint))], axis=-1)
    return TurnVariants(shifts=shifts, joint_shifts=joint_shifts, index=index, lower=lower, upper=upper)


def expand(q: FloatArray, valid: BoolArray, variants: TurnVariants) -> tuple[FloatArray, BoolArray]:
    """Every turn variant of every solution, filtered by the joint limits.

    Parameters
    ----------
    q : (..., B, n) float
        Solutions with revolute angles in (-pi, pi], rad; invalid rows may be NaN.
    valid : (..., B) bool
    variants : TurnVariants

    Returns
    -------
    q : (..., B * V, n) float
        Column b * V + v is branch b shifted by variant v, clamped onto the limits when within
        LIMIT_SLACK of them; NaN rows where invalid.
    valid : (..., B * V) bool
        The branch is valid and the variant lies within the limits.
    """
    q = np.asarray(q, dtype=float)
    valid = np.asarray(valid, dtype=bool)
    n_var = variants.count
    n = q.shape[-1]
    out = np.empty(q.shape[:-1] + (n_var, n))                                  # (..., B, V, n)
    ok = np.repeat(valid[..., None], n_var, axis=-1)                          # (..., B, V)
    # Per joint, shift and test only its few values, then gather them into the variant grid.
    with np.errstate(invalid="ignore"):
        for j in range(n):
            vals = q[..., j, None] + variants.joint_shifts[j]                  # (..., B, K_j)
            lo, hi = variants.lower[j], variants.upper[j]
            inside = (vals >= lo - LIMIT_SLACK) & (vals <= hi + LIMIT_SLACK)
            np.clip(vals, lo, hi, out=vals)
            idx = variants.index[:, j]
            if len(variants.joint_shifts[j]) == 1:
                out[..., j] = vals
                ok &= inside
            else:
                out[..., j] = vals[..., idx]
                ok &= inside[..., idx]
    out[~ok] = np.nan
    shape = q.shape[:-2] + (q.shape[-2] * n_var,)
    return out.reshape(shape + (n,)), ok.reshape(shape)


def variant_of(q: FloatArray, valid: BoolArray, variants: TurnVariants, v: IntArray) -> tuple[FloatArray, BoolArray]:
    """Turn variant v of each solution: what `expand` puts in column b * V + v for branch b, for a
    few solutions instead of every variant of every one (the same arithmetic, so the same values).

    Parameters
    ----------
    q : (..., n) float
        Solutions with revolute angles in (-pi, pi], rad; invalid rows may be NaN.
    valid : (...) bool
    v : (...) int
        The variant of each solution, an index into `variants.shifts`.

    Returns
    -------
    q : (..., n) float, clamped onto the limits when within LIMIT_SLACK of them; NaN rows where invalid.
    valid : (...) bool — the solution is valid and its variant lies within the limits.
    """
    q = np.asarray(q, dtype=float)
    ok = np.array(valid, dtype=bool, copy=True)
    v = np.asarray(v, dtype=np.int64)
    out = np.empty(q.shape)
    with np.errstate(invalid="ignore"):
        for j in range(q.shape[-1]):
            vals = q[..., j] + variants.joint_shifts[j][variants.index[v, j]]
            lo, hi = variants.lower[j], variants.upper[j]
            ok &= (vals >= lo - LIMIT_SLACK) & (vals <= hi + LIMIT_SLACK)
            out[..., j] = np.clip(vals, lo, hi)
    out[~ok] = np.nan
    return out, ok


def filter_limits(q: FloatArray, valid: BoolArray, lower: FloatArray, upper: FloatArray) -> BoolArray:
    """valid & every joint within [lower, upper] (LIMIT_SLACK allowed), for (..., B, n) solutions."""
    q = np.asarray(q, dtype=float)
    with np.errstate(invalid="ignore"):
        inside = np.all((q >= np.asarray(lower) - LIMIT_SLACK) & (q <= np.asarray(upper) + LIMIT_SLACK), axis=-1)
    result: BoolArray = np.asarray(valid, dtype=bool) & inside
    return result
