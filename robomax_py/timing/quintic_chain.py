"""A planar path of quintic Bézier segments end to end (`bezier_construct`), as arclength tables:
points at given arclengths and, on a grid of nodes, the signed curvature and its derivative in
arclength, the latter on both sides of each join (the paper's joins keep the curvature but not its
derivative: kappa' = 0 where a curve starts, whatever it was where the one before ended).

Arclength is integrated by Gauss-Legendre quadrature (16 nodes on each of PANELS panels per
segment, exact to ~1e-13 m on the curves used here) and inverted by Newton's method, so a point at
arclength s is placed to ~1e-12 m: third differences of positions taken 5 ms apart stay exact to
~1e-5 m/s^3 (`frenet_measure`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray, IntArray
from robomax_py.spec import frozen_array
from robomax_py.timing._common import TimingError
from robomax_py.timing.bezier_construct import curvature, hodographs

PANELS = 64
_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)
NEWTON_STEPS = 4
# The grid's curvature tables need lambda to ~1e-12 only: two steps from the panel's interpolation.
GRID_NEWTON_STEPS = 2
# Grid resolution: curvature change (1/m) and change of its derivative (1/m^2) per step at most,
# at the steepest place measured on RESOLUTION_SAMPLES intervals of lambda; at most MAX_STEPS steps
# per segment.
KAPPA_STEP = 0.02
DKAPPA_STEP = 0.2
RESOLUTION_SAMPLES = 256
MAX_STEPS = 5000
# ... but nodes no closer than this (m), unless `step` asks for it.
MIN_STEP_M = 0.002


def _speed(control: FloatArray, lam: FloatArray) -> FloatArray:
    """|d r / d lambda| at lam (k,): the quartic hodograph only."""
    d = 5.0 * np.diff(control, axis=0)
    u = np.asarray(lam, dtype=float)[:, None]
    w = 1.0 - u
    r1 = w**4 * d[0] + 4 * u * w**3 * d[1] + 6 * u**2 * w**2 * d[2] + 4 * u**3 * w * d[3] + u**4 * d[4]
    return np.asarray(np.hypot(r1[:, 0], r1[:, 1]), dtype=float)


def _is_straight(control: FloatArray) -> bool:
    """Evenly spaced collinear control points: arclength is proportional to lambda."""
    steps = np.diff(control, axis=0)
    return bool(np.allclose(steps, steps[0], rtol=0.0, atol=1e-12 * (1.0 + float(np.abs(control).max()))))


def _partial_lengths(control: FloatArray, lo: FloatArray, hi: FloatArray) -> FloatArray:
    """Arclength from lambda = lo to hi (both (k,)), one 16-point Gauss rule each."""
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    lam = (mid[:, None] + half[:, None] * _GL_X[None, :]).ravel()
    sp = _speed(control, lam).reshape(len(lo), len(_GL_X))
    return np.asarray(half * (sp @ _GL_W), dtype=float)


@dataclass(frozen=True, slots=True)
class ChainGrid:
    """Nodes along a chain: arclength s (n+1,) m, signed curvature kappa (n+1,) 1/m, and
    d kappa / ds (1/m^2) of the piece leaving each node (`dk_out`) and of the piece arriving at it
    (`dk_in`); they differ only at joins. `kappa_mid`, `dk_mid` (n,): the same halfway along each
    step."""

    s: FloatArray
    kappa: FloatArray
    dk_out: FloatArray
    dk_in: FloatArray
    kappa_mid: FloatArray
    dk_mid: FloatArray


@dataclass(frozen=True, slots=True, eq=False)
class QuinticChain:
    """Quintic segments end to end: control (m, 6, 2), metres; each must start where the one
    before ends."""

    control: FloatArray
    panel_s: FloatArray          # (m, PANELS + 1) arclength at each panel's start within its segment

    @classmethod
    def of(cls, segments: list[FloatArray] | FloatArray) -> QuinticChain:
        c = np.asarray(segments, dtype=float)
        if c.ndim != 3 or c.shape[1:] != (6, 2) or not np.all(np.isfinite(c)):
            raise TimingError(f"a quintic chain needs finite (m, 6, 2) control points, got shape {c.shape}")
        if len(c) > 1 and float(np.max(np.abs(c[1:, 0] - c[:-1, 5]))) > 1e-9:
            raise TimingError("each segment of a quintic chain must start where the one before ends")
        edges = np.linspace(0.0, 1.0, PANELS + 1)
        table = np.zeros((len(c), PANELS + 1))
        for i, ctrl in enumerate(c):
            table[i, 1:] = np.cumsum(_partial_lengths(ctrl, edges[:-1], edges[1:]))
        if np.any(table[:, -1] <= 0.0):
            raise TimingError("a segment of a quintic chain has zero length")
        return cls(frozen_array(c), frozen_array(table))

    @property
    def lengths(self) -> FloatArray:
        return np.asarray(self.panel_s[:, -1], dtype=float)

    @property
    def starts(self) -> FloatArray:
        """(m + 1,) arclength where each segment starts, and the total length last."""
        return np.concatenate([[0.0], np.cumsum(self.lengths)])

    @property
    def length(self) -> float:
        return float(self.starts[-1])

    def _lambda(self, i: int, s_local: FloatArray, newton_steps: int = NEWTON_STEPS) -> FloatArray:
        """lambda (k,) of segment i at arclengths s_local (k,) from its start."""
        ctrl, table = self.control[i], self.panel_s[i]
        edges = np.linspace(0.0, 1.0, PANELS + 1)
        s_local = np.clip(np.asarray(s_local, dtype=float), 0.0, table[-1])
        if _is_straight(ctrl):
            return np.asarray(s_local / table[-1], dtype=float)
        p = np.clip(np.searchsorted(table, s_local, side="right") - 1, 0, PANELS - 1)
        lam = edges[p] + (s_local - table[p]) / (table[p + 1] - table[p]) / PANELS
        for _ in range(newton_steps):
            err = table[p] + _partial_lengths(ctrl, edges[p], lam) - s_local
            lam = np.clip(lam - err / _speed(ctrl, lam), edges[p], edges[p + 1])
        return np.asarray(lam, dtype=float)

    def _locate(self, s: FloatArray) -> tuple[IntArray, FloatArray]:
        """Segment index (k,) and local arclength (k,) of arclengths s (k,)."""
        starts = self.starts
        s = np.clip(np.asarray(s, dtype=float), 0.0, starts[-1])
        seg = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(self.control) - 1).astype(np.int64)
        return seg, np.asarray(s - starts[seg], dtype=float)

    def points(self, s: FloatArray) -> FloatArray:
        """Points (k, 2) m at arclengths s (k,)."""
        seg, local = self._locate(s)
        out = np.empty((len(seg), 2))
        for i in np.unique(seg):
            sel = seg == i
            out[sel] = hodographs(self.control[i], self._lambda(int(i), local[sel]))[0]
        return out

    def nodes(self, step: float) -> list[FloatArray]:
        """Per segment, the arclengths (from its start) of its nodes: at most `step` apart, and
        closer where the curvature changes fast, so that from one node to the next it changes by
        at most KAPPA_STEP and its derivative by at most DKAPPA_STEP (a profile checks its limits
        at the nodes and halfway: a sharp turn between them would go unseen), down to MIN_STEP_M.
        The nodes equidistribute that density, measured on RESOLUTION_SAMPLES intervals of lambda."""
        if not (step > 0.0 and np.isfinite(step)):
            raise TimingError(f"the grid step must be finite and > 0, got {step}")
        lam = np.linspace(0.0, 1.0, RESOLUTION_SAMPLES + 1)
        out = []
        for ctrl, length in zip(self.control, self.lengths, strict=True):
            if _is_straight(ctrl):
                out.append(np.linspace(0.0, length, max(2, int(np.ceil(length / step))) + 1))
                continue
            kappa, _, dkappa = curvature(ctrl, lam)
            s_tab = np.concatenate([[0.0], np.cumsum(_partial_lengths(ctrl, lam[:-1], lam[1:]))])
            ds = np.diff(s_tab)
            density = np.maximum.reduce([np.full(len(ds), 1.0 / step), np.abs(np.diff(kappa)) / ds / KAPPA_STEP,
                                         np.abs(np.diff(dkappa)) / ds / DKAPPA_STEP])
            density = np.minimum(density, max(1.0 / step, 1.0 / MIN_STEP_M))
            level = np.concatenate([[0.0], np.cumsum(density * ds)])
            count = min(max(2, int(np.ceil(level[-1]))), MAX_STEPS)
            local = np.interp(np.linspace(0.0, level[-1], count + 1), level, s_tab)
            local[-1] = length
            out.append(local)
        return out

    def grid(self, step: float) -> ChainGrid:
        """The nodes of `nodes`, every join a node, with the curvature tables there."""
        s_parts, k_parts, dk_parts, mid_parts = [], [], [], []
        for i, (s0, local) in enumerate(zip(self.starts, self.nodes(step), strict=False)):
            ctrl = self.control[i]
            kappa, _, dkappa = curvature(ctrl, self._lambda(i, local, GRID_NEWTON_STEPS))
            s_parts.append(s0 + local)
            k_parts.append(kappa)
            dk_parts.append(dkappa)
            kappa_mid, _, dk_mid = curvature(ctrl, self._lambda(i, 0.5 * (local[1:] + local[:-1]), GRID_NEWTON_STEPS))
            mid_parts.append((kappa_mid, dk_mid))
        s = np.concatenate([p if i == 0 else p[1:] for i, p in enumerate(s_parts)])
        kappa = np.concatenate([p if i == 0 else p[1:] for i, p in enumerate(k_parts)])
        dk_out = np.concatenate([p[:-1] for p in dk_parts] + [dk_parts[-1][-1:]])
        dk_in = np.concatenate([dk_parts[0][:1]] + [p[1:] for p in dk_parts])
        kappa_mid = np.concatenate([m[0] for m in mid_parts])
        dk_mid = np.concatenate([m[1] for m in mid_parts])
        return ChainGrid(frozen_array(s), frozen_array(kappa), frozen_array(dk_out), frozen_array(dk_in),
                         frozen_array(kappa_mid), frozen_array(dk_mid))

    def geometry(self, step: float) -> tuple[FloatArray, FloatArray]:
        """Node arclengths s (n+1,) and the table (n+1, 5) the profile kernels read: per node kappa,
        dk_out, dk_in, and for the step leaving it kappa and d kappa / ds at its middle."""
        g = self.grid(step)
        geo = np.zeros((len(g.s), 5))
        geo[:, 0], geo[:, 1], geo[:, 2] = g.kappa, g.dk_out, g.dk_in
        geo[:-1, 3], geo[:-1, 4] = g.kappa_mid, g.dk_mid
        return np.asarray(g.s, dtype=float), geo
