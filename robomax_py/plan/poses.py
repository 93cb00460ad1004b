"""Seams x orientation grid -> candidate TCP poses (docs/cell-files.md, "Seams and spots").

For a spot with outward normal n and seam direction d the nominal TCP frame has z = -n (the electrode
closes into the sheet), x = d orthogonal to n, y = z x x. A candidate orientation is
R = R_nominal · Rx(alpha) · Ry(beta) · Rz(gamma). A seam whose gun may stand on either side of the
sheet (`SeamSpec.either_side`) has the grid twice: the second time turned 180 deg about x, the
nominal z then along +n, alpha = the tilt ± 180 deg.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.spec import SeamSpec, SpotSpec
from robomax_py.transforms import rot_x, rot_y, rot_z

# Two grid orientations closer than this (rad) are the same (gamma = -180 and +180 deg, say).
SAME_ORIENTATION_RAD = 1e-9


@dataclass(frozen=True, slots=True, eq=False)
class OrientationGrid:
    """The distinct orientations of a seam's tolerance grid, in grid order.

    angles : (m, 3) float, rad — (alpha, beta, gamma) of each distinct orientation
    R_offset : (m, 3, 3) float — Rx(alpha) Ry(beta) Rz(gamma)
    """

    angles: FloatArray
    R_offset: FloatArray

    def __len__(self) -> int:
        return len(self.angles)


def axis_samples(lo: float, hi: float, grid: int) -> FloatArray:
    """`grid` evenly spaced values from lo to hi, ends included; one value for an empty range."""
    if hi - lo <= SAME_ORIENTATION_RAD or grid == 1:
        return np.array([(lo + hi) / 2.0]) if grid == 1 else np.array([lo])
    return np.linspace(lo, hi, grid)


def orientation_grid(seam: SeamSpec) -> OrientationGrid:
    """grid^3 samples of (alpha, beta, gamma), duplicate rotations removed (first kept).

    The nominal orientation (0, 0, 0) is first when the grid contains it, so stable tie-breaking
    prefers it.
    """
    alphas = axis_samples(-seam.alpha_max, seam.alpha_max, seam.grid)
    betas = axis_samples(-seam.beta_max, seam.beta_max, seam.grid)
    gammas = axis_samples(seam.gamma_range[0], seam.gamma_range[1], seam.grid)
    combos = np.array([(a, b, g) for a in alphas for b in betas for g in gammas])
    # Order by distance from nominal so that ties between equally good orientations resolve
    # towards the nominal one (the published baseline's choice); stable for equal distances.
    order = np.argsort(np.abs(combos).sum(axis=1), kind="stable")
    combos = combos[order]
    if seam.either_side:
        # The other side's orientations after this side's (ties still resolve toward the nominal):
        # Rx(pi + alpha), alpha kept in (-pi, pi].
        turned = combos.copy()
        turned[:, 0] = np.where(turned[:, 0] > 0.0, turned[:, 0] - np.pi, turned[:, 0] + np.pi)
        combos = np.vstack([combos, turned])
    # Orientations pinned by a spot (cell-file extension) join the grid after its own samples.
    pins = [np.array(spot.angles) for spot in seam.spots if spot.angles is not None]
    if pins:
        combos = np.vstack([combos, *pins])
    Rs = np.array([rot_x(a) @ rot_y(b) @ rot_z(g) for a, b, g in combos]).reshape(-1, 3, 3)
    kept = np.zeros(len(combos), dtype=bool)
    kept_R = np.empty_like(Rs)                # the kept rotations so far, compared in one step
    n = 0
    for i, R in enumerate(Rs):
        if n and np.abs(kept_R[:n] - R).max(axis=(1, 2)).min() < SAME_ORIENTATION_RAD:
            continue
        kept[i] = True
        kept_R[n] = R
        n += 1
    return OrientationGrid(angles=combos[kept].astype(float), R_offset=kept_R[:n].copy())


def pinned_index(grid: OrientationGrid, spot: SpotSpec) -> int | None:
    """The grid orientation a spot's pinned angles name (None: not pinned)."""
    if spot.angles is None:
        return None
    a, b, g = spot.angles
    R = rot_x(a) @ rot_y(b) @ rot_z(g)
    return int(np.argmin(np.abs(grid.R_offset - R).reshape(len(grid), -1).max(axis=1)))


def nominal_rotation(spot: SpotSpec) -> FloatArray:
    """(3, 3) nominal TCP orientation at a spot, world frame."""
    z = -np.asarray(spot.normal, dtype=float)
    x = np.asarray(spot.direction, dtype=float)
    x = x - np.dot(x, z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])


def spot_poses(spots: tuple[SpotSpec, ...], grid: OrientationGrid) -> FloatArray:
    """Candidate TCP poses in the world frame.

    Returns
    -------
    (n_spot, m, 4, 4) float
        T_world_tcp for every spot and every distinct grid orientation, metres.
    """
    out = np.zeros((len(spots), len(grid), 4, 4))
    for i, spot in enumerate(spots):
        out[i, :, :3, :3] = nominal_rotation(spot) @ grid.R_offset
        out[i, :, :3, 3] = spot.xyz
        out[i, :, 3, 3] = 1.0
    return out


def approach_poses(T_world_tcp: FloatArray, approach: float) -> FloatArray:
    """Poses `approach` metres along +TCP z from each spot pose, (..., 4, 4).

    The gun arrives from (and leaves to) the fixed electrode's side: with the moving electrode open,
    a C-gun moved along -z towards the sheet never passes an electrode through the sheet.
    """
    out = np.array(T_world_tcp, dtype=float, copy=True)
    out[..., :3, 3] += approach * out[..., :3, 2]
    return out
