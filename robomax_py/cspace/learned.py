"""The learned C-space model of the ROBOMAX method: a point obstacle's C-obstacle as profiles of its
distance, interpolated by an RBF network with triangular basis functions.

Conjugate vector model
----------------------
A point p is seen from the arm's "unbiased virtual base" V (on the A1 axis at the height of A2) as
its distance d = |p - V|, its azimuth alpha about A1 and its elevation e above V's horizontal plane.
Turning the point about A1 by alpha is turning the arm by alpha (exact); raising it by e is, near
enough, turning A2 by e (exact only when A2's axis passes through V: it is offset from A1 by the
shoulder offset, so the model is weakest near the base). So the C-obstacle of p is taken to be

    (q2 - e, q3) in S_b(d)   for q1 - alpha in band b,

with the circle of q1 - alpha cut into bands (`band_deg`) and S_b(d) the (q2, q3) set where the arm
touches a sphere of radius rho at (d, 0, 0) for some q1 in the band: per column of the training q2
grid, one q3 interval [Q3lo, Q3hi] (its hull, so a profile over-blocks rather than misses). One
band for the whole circle is the paper's q1 interval with one profile; narrower bands follow the
profile's change with q1 (the gun swings sideways as A1 turns off the point). Signs follow the
axes' directions at q = 0.

Training
--------
For distances d_m every `d_step` from 0 to the arm's farthest point, the exact checker (coal, with
the pre-filter) tests the robot and its tool with the wrist fixed against a sphere of radius rho at
(d_m, 0, 0) on a training grid of (q1, q2, q3); the profile vector of d_m is
[Q3lo per (band, column), Q3hi per (band, column)] (an empty interval is stored inverted, beyond
the grid). A two-layer RBF network with triangular basis functions f_k(d) = 1 - |d - c_k| / sigma_k
(sigma_k the gap to the neighbouring centre on that side) maps d to the profile vector; its output
weights are least squares, `numpy.linalg.lstsq` (the paper's w = (F^T F)^-1 F^T Q); it starts with
`start_neurons` centres spread over the distances and adds a centre at the worst-fitted distance
until every profile value is within `tolerance_steps` grid steps, or every distance is a centre, or
it has `max_neurons` (the paper starts from k' = 7-8 neurons and grows them to its threshold; it
does not state the final count).

Using it
--------
A cell's objects become surface points (`points.surface_points`); each point's profiles are read at
d and at d +- d_step (their union: a point between two training distances is covered by both), its
bands and columns are shifted by its azimuth and elevation and marked in the map (per band, the
union of the points' (q2, q3) sets at each q1 cell the band reaches, a chunk of points at a time).
The sphere radius rho is the cell's clearance plus the points' cover radius plus `inflation`: with
that, the points' spheres contain every object surface, and the inflation absorbs the model's
approximations. Accuracy is measured against the exact map, never assumed.
"""

from __future__ import annotations

import hashlib
import math
import time
from dataclasses import dataclass, replace

import coal
import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.cspace.exact import BLOCK, CSpaceMap
from robomax_py.cspace.grid import CSpaceError, CSpaceGrid, check_arm
from robomax_py.robot import RobotModel
from robomax_py.robot.ik._chain import joint_axes_at_zero
from robomax_py.spec import CellSpec, frozen_array
from robomax_py.world.acm import CollisionOptions
from robomax_py.world.bounds import support_points
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import Scene, SceneObject, build_scene

MODEL_VERSION = 3
CHUNK = 1024                 # points marked at a time
# Training: no self pairs are needed (obstacle pairs only), so no ACM samples or proof.
_TRAIN_OPTIONS = CollisionOptions(acm_samples=1, acm_proof_joints=0)


@dataclass(frozen=True, slots=True)
class TrainingSettings:
    """How a model is trained (degrees and metres as a user gives them)."""

    q1_step_deg: float = 4.0
    q23_step_deg: float = 3.0
    band_deg: float = 20.0            # the q1 circle is cut into bands this wide, one (q2, q3) profile each
    d_step: float = 0.05
    start_neurons: int = 8
    tolerance_steps: float = 1.0      # profile fit: every value within this many grid steps
    max_neurons: int | None = None    # stop growing here even if the fit is worse


# A training grid ~20x cheaper than the standard one (2.3 M checks for the KR 125 with its C-gun
# instead of 75 M), for planning and tests where the exact check has the last word.
COARSE_TRAINING = TrainingSettings(q1_step_deg=10.0, q23_step_deg=8.0, d_step=0.1, band_deg=30.0)


@dataclass(frozen=True, slots=True)
class VirtualBase:
    """The arm's unbiased virtual base and the signs that turn azimuth and elevation into q1, q2."""

    origin: FloatArray          # (3,) base frame, m
    q1_sign: float              # +1 when A1 turns about +z
    q2_sign: float              # +1 when raising a point in the arm's plane is a positive A2 turn

    @staticmethod
    def of(robot: RobotModel) -> VirtualBase:
        axes = joint_axes_at_zero(robot.model, robot.flange_frame_id)
        a1, p1, a2, p2 = axes.u[0], axes.p[0], axes.u[1], axes.p[1]
        origin = np.array([p1[0], p1[1], p2[2]], dtype=float)
        q1_sign = 1.0 if a1[2] > 0 else -1.0
        # Raising a point on +x towards +z turns it about -y; A2 at q = 0 turns about a2.
        q2_sign = 1.0 if float(a2 @ np.array([0.0, -1.0, 0.0])) > 0 else -1.0
        return VirtualBase(origin, q1_sign, q2_sign)

    def coordinates(self, points: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(d, azimuth, elevation) of (P, 3) points in the base frame: m, rad, rad."""
        r = np.asarray(points, dtype=float) - self.origin
        flat = np.hypot(r[:, 0], r[:, 1])
        return np.linalg.norm(r, axis=1), np.arctan2(r[:, 1], r[:, 0]), np.arctan2(r[:, 2], flat)


@dataclass(frozen=True, slots=True)
class LearnedModel:
    """A trained model: the network (centres, weights) over the training grid's profile layout."""

    key: str                    # hash of everything it was trained from
    base: VirtualBase
    wrist: FloatArray           # (3,) rad
    radius: float               # m, the training sphere's radius
    q2: FloatArray              # (C,) training q2 values, rad (absolute, the point at elevation 0)
    q3: FloatArray              # (T,) training q3 values, rad
    q1_step: float              # rad
    bands: FloatArray           # (B + 1,) band edges of q1 - azimuth, rad, -pi .. pi
    d_step: float               # m
    d_max: float                # m: beyond this a point cannot touch the arm
    centres: FloatArray         # (K,) m
    weights: FloatArray         # (K, 2 B C): Q3lo per (band, column), then Q3hi per (band, column)
    train_cpu_seconds: float
    train_checks: int
    fit_error_steps: float      # largest profile error over the training distances, grid steps

    def profiles(self, d: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(m, B, C) Q3lo and Q3hi (rad) per q1 band and q2 column at distances d; lo > hi: empty."""
        # At most two neighbouring basis functions are nonzero at any d: the network's output is the
        # blend of their two weight rows (the same values as `_basis(d, centres) @ weights`).
        d = np.atleast_1d(np.asarray(d, dtype=float))
        c = self.centres
        if len(c) == 1:
            out = np.repeat(self.weights, len(d), axis=0)
        else:
            k = np.clip(np.searchsorted(c, d, side="right") - 1, 0, len(c) - 2)
            t = np.clip((d - c[k]) / (c[k + 1] - c[k]), 0.0, 1.0)[:, None]
            out = (1.0 - t) * self.weights[k] + t * self.weights[k + 1]
        B, C = len(self.bands) - 1, len(self.q2)
        return out[:, :B * C].reshape(-1, B, C), out[:, B * C:].reshape(-1, B, C)


def model_key(robot: RobotModel, scene: Scene, wrist: FloatArray, radius: float, settings: TrainingSettings) -> str:
    """SHA-256 over what a model depends on: the chain, the arm's and the tool's pieces, the wrist,
    the sphere radius and the training settings."""
    h = hashlib.sha256()
    model = robot.model
    h.update(f"v{MODEL_VERSION};{robot.name};{settings}".encode())
    for j in range(1, model.njoints):
        h.update(model.joints[j].shortname().encode())
        h.update(np.asarray(model.jointPlacements[j].homogeneous, dtype=float).round(12).tobytes())
    h.update(np.asarray(robot.limits.lower).round(12).tobytes() + np.asarray(robot.limits.upper).round(12).tobytes())
    for g in robot.collision_model.geometryObjects:
        h.update(np.asarray(g.placement.homogeneous).round(12).tobytes())
        h.update(np.asarray(support_points(g.geometry)).round(9).tobytes())
    h.update(np.asarray(robot.T_flange_tcp).round(12).tobytes())
    for geom in (*scene.tool.body, *scene.tool.tips):
        h.update(np.asarray(support_points(geom)).round(9).tobytes())
    h.update(np.asarray(wrist, dtype=float).round(12).tobytes() + np.float64(round(radius, 12)).tobytes())
    return h.hexdigest()


def tool_scene(cell: CellSpec, robot: RobotModel) -> Scene:
    """The cell's scene without its objects: the robot's tool, which is all a model depends on."""
    return build_scene(replace(cell, objects=(), dynamic=()), robot)


def train(scene0: Scene, robot: RobotModel, wrist: FloatArray, radius: float,
          settings: TrainingSettings = TrainingSettings()) -> LearnedModel:
    """Train the model of `robot` with the tool of `scene0` (`tool_scene`) and the wrist fixed (see
    the module docstring)."""
    check_arm(robot)
    c0 = time.process_time()
    wrist = np.asarray(wrist, dtype=float)
    base = VirtualBase.of(robot)
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    q1_step, q23_step = math.radians(settings.q1_step_deg), math.radians(settings.q23_step_deg)
    dq1 = np.arange(-math.pi, math.pi, q1_step)
    # A point's elevation e in [-pi/2, pi/2] shifts its A2 profile by e: the columns must cover the
    # limits widened by that much, or a point below or above V loses the columns past the limits.
    q2 = _axis(lo[1] - math.pi / 2, hi[1] + math.pi / 2, q23_step)
    q3 = _axis(lo[2], hi[2], q23_step)
    d_max = _reach_from(base, robot, scene0) + radius
    distances = np.arange(0.0, d_max + settings.d_step, settings.d_step)
    grid = CSpaceGrid(axes=(base.q1_sign * dq1, q2, q3), wrist=wrist)   # q1 values in the arm's own sense
    n_bands = max(1, round(360.0 / settings.band_deg))
    bands = np.linspace(-math.pi, math.pi, n_bands + 1)
    band_of = np.minimum(np.searchsorted(bands, dq1, side="right") - 1, n_bands - 1)
    rows, checks = [], 0
    for d in distances:
        occupied = _occupancy(scene0, robot, base, grid, float(d), radius)
        checks += occupied.size
        rows.append(_profile(occupied, band_of, n_bands, q3))
    targets = np.array(rows)
    centres, weights, error = _fit(distances, targets, settings, q23_step)
    return LearnedModel(
        key=model_key(robot, scene0, wrist, radius, settings), base=base, wrist=wrist, radius=radius, q2=q2, q3=q3,
        q1_step=q1_step, bands=bands, d_step=settings.d_step, d_max=d_max, centres=centres, weights=weights,
        train_cpu_seconds=time.process_time() - c0, train_checks=checks, fit_error_steps=error,
    )


def learned_map(model: LearnedModel, points: FloatArray, grid: CSpaceGrid) -> CSpaceMap:
    """The map of the cell whose surfaces are `points`, from the model (obstacles only; the
    self-contact mask is left empty: it does not depend on the cell)."""
    if not np.allclose(grid.wrist, model.wrist, atol=1e-12):
        raise CSpaceError("the model was trained for another wrist")
    w0, c0 = time.perf_counter(), time.process_time()
    d, alpha, elev = model.base.coordinates(points)
    near = d <= model.d_max
    d, alpha, elev = d[near], alpha[near], elev[near]
    r = grid.resolution
    q1g, q2g, q3g = grid.axes
    C = len(model.q2)
    # Each point's profiles: the union at d and d +- d_step (inverted intervals stay empty).
    order = np.argsort(d, kind="stable")          # points of like distance share their bands in a chunk
    d, alpha, elev = d[order], alpha[order], elev[order]
    marked = np.zeros((r, r * r), dtype=bool)
    step2 = float(model.q2[1] - model.q2[0]) if C > 1 else 1.0
    step3 = float(model.q3[1] - model.q3[0]) if len(model.q3) > 1 else 0.0
    half1 = model.q1_step / 2
    edges = model.bands
    for a in range(0, len(d), CHUNK):
        s = slice(a, a + CHUNK)
        n = len(d[s])
        los, his = zip(*(model.profiles(np.clip(d[s] + k * model.d_step, 0.0, None)) for k in (-1, 0, 1)))
        q3lo, q3hi = np.minimum.reduce(los), np.maximum.reduce(his)          # (n, B, C)
        rel = _wrap(model.base.q1_sign * q1g[None, :] - alpha[s, None])     # (n, r)
        # q2: the training column of q2 - shift, and its neighbour, united.
        col = (q2g[None, :] - model.base.q2_sign * elev[s, None] - model.q2[0]) / step2
        c_lo = np.floor(col).astype(np.int64)
        rows = np.arange(n)[:, None]
        for b in range(len(edges) - 1):
            lo_b, hi_b = q3lo[:, b, :], q3hi[:, b, :]                       # (n, C)
            live = (lo_b <= hi_b).any(axis=1)
            if not live.any():
                continue
            lo3 = np.full(col.shape, np.inf)
            hi3 = np.full(col.shape, -np.inf)
            for c in (c_lo, c_lo + 1):
                ok = (c >= 0) & (c < C)
                cc = np.clip(c, 0, C - 1)
                lo3 = np.where(ok, np.minimum(lo3, lo_b[rows, cc]), lo3)
                hi3 = np.where(ok, np.maximum(hi3, hi_b[rows, cc]), hi3)
            in_q1 = (rel >= edges[b] - half1) & (rel <= edges[b + 1] + half1)
            if b == 0:
                in_q1 |= rel >= math.pi - half1
            if b == len(edges) - 2:
                in_q1 |= rel <= -math.pi + half1
            keep = live & in_q1.any(axis=1)
            if not keep.any():
                continue
            in_q23 = (q3g[None, None, :] >= lo3[keep][:, :, None] - step3 / 2) & \
                (q3g[None, None, :] <= hi3[keep][:, :, None] + step3 / 2)
            flat = in_q23.reshape(-1, r * r)
            in_q1 = in_q1[keep]
            # Each q1 cell the band reaches: the union of its points' (q2, q3) sets (a band covers a
            # few q1 cells, so this is a few passes over the points rather than r).
            for i in np.flatnonzero(in_q1.any(axis=0)):
                marked[i] |= flat[in_q1[:, i]].any(axis=0)
    blocked = marked.reshape(r, r, r)
    return CSpaceMap(grid=grid, obstacle=blocked, self_contact=np.zeros_like(blocked), method="learned",
                     cpu_seconds=time.process_time() - c0, wall_seconds=time.perf_counter() - w0, checks=0)


# ---------------------------------------------------------------------------------- internals


def _axis(lo: float, hi: float, step: float) -> FloatArray:
    n = max(2, math.ceil((hi - lo) / step) + 1)
    return np.linspace(lo, hi, n)


def _wrap(a: FloatArray) -> FloatArray:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _reach_from(base: VirtualBase, robot: RobotModel, scene: Scene) -> float:
    """m: a bound on how far any arm or tool point gets from the virtual base, in any pose.

    V and joint 1's origin are both on A1's axis; from there the triangle inequality along the
    chain: |x - V| <= |o_1 - V| + the joint offsets from joint 1 to x's joint + x's distance from
    that joint's origin."""
    model = robot.model
    o1 = np.asarray(model.jointPlacements[1].translation, dtype=float)
    offsets = np.zeros(model.njoints)
    for j in range(2, model.njoints):
        offsets[j] = offsets[int(model.parents[j])] + float(np.linalg.norm(model.jointPlacements[j].translation))
    reach = 0.0
    pieces = [(int(g.parentJoint), np.asarray(g.placement.homogeneous), g.geometry)
              for g in robot.collision_model.geometryObjects]
    flange = model.frames[scene.flange_frame_id]
    pieces += [(int(flange.parentJoint), np.asarray(flange.placement.homogeneous), geom)
               for geom in (*scene.tool.body, *scene.tool.tips)]
    for j, placement, geom in pieces:
        if j == 0:
            continue
        pts = support_points(geom, placement)
        reach = max(reach, offsets[j] + float(np.linalg.norm(pts, axis=1).max()))
    return float(np.linalg.norm(o1 - base.origin)) + reach


def _occupancy(scene0: Scene, robot: RobotModel, base: VirtualBase, grid: CSpaceGrid, d: float,
               radius: float) -> np.ndarray:
    """(n1, C, T) bool: the arm touches the sphere of `radius` at (d, 0, 0) from the virtual base."""
    pose = np.eye(4)
    pose[:3, 3] = base.origin + np.array([d, 0.0, 0.0])
    probe = SceneObject(name="cspace_probe", pieces=(coal.Sphere(radius),), T_base_object=frozen_array(pose),
                        workpiece=False, representation="primitive")
    world = CollisionWorld(robot, replace(scene0, obstacles=(probe,), dynamic=()), 0.0,
                           _TRAIN_OPTIONS).restricted(obstacles=True, self_pairs=False)
    out = np.zeros(grid.size, dtype=bool)
    for a in range(0, grid.size, BLOCK):
        b = min(a + BLOCK, grid.size)
        out[a:b] = ~world.are_free(grid.configs(a, b))
    r1, r2, r3 = (len(ax) for ax in grid.axes)
    return out.reshape(r1, r2, r3)


def _profile(occupied: np.ndarray, band_of: np.ndarray, n_bands: int, q3: FloatArray) -> FloatArray:
    """[Q3lo per (band, column), Q3hi per (band, column)] of one training occupancy (n1, C, T), rad:
    the hull of the occupied q3 values over the band's q1 samples; an empty interval is stored
    inverted one step beyond the grid, so interpolation towards it shrinks the interval."""
    step3 = float(q3[1] - q3[0])
    C = occupied.shape[1]
    lo = np.full((n_bands, C), q3[-1] + step3)
    hi = np.full((n_bands, C), q3[0] - step3)
    for b in range(n_bands):
        union = occupied[band_of == b].any(axis=0)            # (C, T)
        has = union.any(axis=1)
        first = np.argmax(union, axis=1)
        last = union.shape[1] - 1 - np.argmax(union[:, ::-1], axis=1)
        lo[b, has], hi[b, has] = q3[first[has]], q3[last[has]]
    return np.concatenate([lo.ravel(), hi.ravel()])


def _basis(d: FloatArray, centres: FloatArray) -> FloatArray:
    """(m, K) triangular basis: 1 at its centre, 0 at the neighbouring centres (their gap is sigma on
    each side); the outermost functions stay 1 beyond the ends."""
    d = np.atleast_1d(d)
    K = len(centres)
    out = np.zeros((len(d), K))
    for k in range(K):
        c = centres[k]
        left = centres[k] - centres[k - 1] if k > 0 else math.inf
        right = centres[k + 1] - centres[k] if k + 1 < K else math.inf
        x = d - c
        out[:, k] = np.where(x < 0, 1.0 + x / left, 1.0 - x / right)
    return np.clip(out, 0.0, 1.0)


def _fit(distances: FloatArray, targets: FloatArray, settings: TrainingSettings,
         q23_step: float) -> tuple[FloatArray, FloatArray, float]:
    """Centres and least-squares output weights, neurons added at the worst-fitted distance."""
    scale = q23_step
    n = len(distances)
    k0 = min(max(2, settings.start_neurons), n, max(2, settings.max_neurons or n))
    chosen = set(np.round(np.linspace(0, n - 1, k0)).astype(int).tolist())
    while True:
        idx = np.array(sorted(chosen))
        centres = distances[idx]
        F = _basis(distances, centres)
        weights, *_ = np.linalg.lstsq(F, targets, rcond=None)
        err = (np.abs(F @ weights - targets) / scale).max(axis=1)
        error = float(err.max())
        full = len(chosen) == n or (settings.max_neurons is not None and len(chosen) >= settings.max_neurons)
        if error <= settings.tolerance_steps or full:
            return centres, np.asarray(weights, dtype=float), error
        err[idx] = -1.0                  # a neuron where the fit is worst, among distances without one
        chosen.add(int(np.argmax(err)))


def to_arrays(model: LearnedModel) -> dict[str, np.ndarray]:
    """The model as named arrays (for numpy's .npz), readable back by `from_arrays`."""
    return {
        "version": np.array(MODEL_VERSION), "key": np.array(model.key), "origin": model.base.origin,
        "signs": np.array([model.base.q1_sign, model.base.q2_sign]), "wrist": model.wrist,
        "scalars": np.array([model.radius, model.q1_step, model.d_step, model.d_max, model.train_cpu_seconds,
                             float(model.train_checks), model.fit_error_steps]),
        "q2": model.q2, "q3": model.q3, "bands": model.bands, "centres": model.centres, "weights": model.weights,
    }


def from_arrays(arrays: dict[str, np.ndarray], key: str) -> LearnedModel | None:
    """The model stored by `to_arrays`, or None when it is of another version or key, or malformed."""
    try:
        if int(arrays["version"]) != MODEL_VERSION or str(arrays["key"]) != key:
            return None
        radius, q1_step, d_step, d_max, cpu, checks, error = (float(v) for v in arrays["scalars"])
        q1_sign, q2_sign = (float(v) for v in arrays["signs"])
        model = LearnedModel(
            key=key, base=VirtualBase(np.asarray(arrays["origin"], dtype=float), q1_sign, q2_sign),
            wrist=np.asarray(arrays["wrist"], dtype=float), radius=radius, q2=np.asarray(arrays["q2"], dtype=float),
            q3=np.asarray(arrays["q3"], dtype=float), q1_step=q1_step, bands=np.asarray(arrays["bands"], dtype=float),
            d_step=d_step, d_max=d_max,
            centres=np.asarray(arrays["centres"], dtype=float), weights=np.asarray(arrays["weights"], dtype=float),
            train_cpu_seconds=cpu, train_checks=int(checks), fit_error_steps=error,
        )
    except (KeyError, ValueError, TypeError):
        return None
    shape = (len(model.centres), 2 * (len(model.bands) - 1) * len(model.q2))
    if model.weights.shape != shape or not np.isfinite(model.weights).all():
        return None
    return model
