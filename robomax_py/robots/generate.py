#!/usr/bin/env python
"""Generate the robot and tool library: URDFs, meshes and YAML for kr125, kr16 and spot_gun_c.

Run from anywhere:  ``python robots/generate.py [--out DIR]``  (DIR defaults to this file's folder).
The output is deterministic: running the script twice gives byte-identical files, which
``tests/robot/test_robot_files.py`` checks against the committed copies.

Kinematics
----------
Each URDF is generated from the OPW parameters in its ``robot.yaml`` so that Pinocchio's forward
kinematics of frame ``tool0`` equals ``robomax_py.robot.ik.opw.opw_fk`` to round-off. The OPW convention
(Brandstötter, Angerer, Hofbaur 2014; opw_kinematics) has the paper angle
``theta = q * sign - offset``; at ``theta = 0`` the arm points straight up. Every link frame of the
URDF *is* the paper's link frame: joint ``i`` carries a fixed rotation ``-offset_i`` about its axis in
its origin and the axis ``sign_i * unit axis``, so ``R_origin * R(sign * q) = R(theta)``.
Hence in the paper's zero pose all link frames are parallel to the base frame, which is where the
meshes are modelled (``_ArmGeometry``) before being shifted into their link frames.

Meshes
------
Visual meshes are unions of closed shells (tubes, lofts, boxes) shaped like a cast robot link;
no booleans, so they are cheap and exact to regenerate. Collision geometry is 1-4 convex hulls per
link, each the hull of a named group of visual shells, so it encloses the visual mesh by
construction. The gun's ``body.stl`` and ``tips.stl`` are unions of separate convex shells that
never share a vertex, so ``split()`` recovers the convex pieces.
"""

from __future__ import annotations

import argparse
import math
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import numpy.typing as npt
import trimesh

FloatArray = npt.NDArray[np.float64]
Point = Sequence[float] | FloatArray

# Segments around a full circle. 40 keeps every link STL well under 300 KB while the
# cylinders still look round in a viewer.
CIRCLE_SEGMENTS = 40
# Segments per rounded corner of a rounded rectangle.
CORNER_SEGMENTS = 6


# ----------------------------------------------------------------------------------------------
# Robot data
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class ArmData:
    """Everything that differs between the two arms.

    Lengths in metres, angles in degrees (converted where they enter the URDF).
    """

    name: str
    title: str
    payload_kg: float
    # OPW lengths, m.
    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    offsets_deg: tuple[float, ...]
    sign_corrections: tuple[int, ...]
    lower_deg: tuple[float, ...]
    upper_deg: tuple[float, ...]
    velocity_deg_s: tuple[float, ...]
    effort_nm: tuple[float, ...]
    acceleration_deg_s2: tuple[float, ...]
    jerk_deg_s3: tuple[float, ...]
    masses_kg: tuple[float, ...]  # base_link, link_1 .. link_6
    # Shape: width scale relative to the KR 125 (1.0), base height (A1 bearing), A4 bearing
    # distance in front of A3, flange radius and thickness, counterbalance on/off.
    width: float
    base_height: float
    a4_bearing: float
    flange_radius: float
    flange_thickness: float
    counterbalance: bool
    yaml_header: str
    params_comment: str
    limits_comment: str
    urdf_comment: str
    # Joint limits with the rated payload (robot.yaml `limits.loaded`); None: not given.
    loaded_scale: tuple[float, float, float] | None = None    # velocity, acceleration, jerk fractions


KUKA_OFFSETS_DEG = (0.0, -90.0, 0.0, 0.0, 0.0, 0.0)
KUKA_SIGNS = (-1, 1, 1, -1, 1, -1)

KR125 = ArmData(
    name="kr125",
    title="KUKA KR 125/2-class six-axis spot-welding arm (reach 2.41 m to the wrist point)",
    payload_kg=125.0,
    # FreeCAD Robot workbench, src/Mod/Robot/Lib/Kuka/kr_125.csv (public DH table of the KR 125):
    # a=410 d=865 (A1->A2), a=1000 (A2->A3), a=45 with alpha=+90, theta=-90 (A3->A4),
    # d=-1000 (A3->wrist), d=-210 (wrist->flange). 410 + 1000 + 1000 = 2410 mm, the KR 125/2 reach.
    # Sign of a2: the same FreeCAD table gives the KR 16 a=-35, which ROS-Industrial's
    # kuka_experimental opw_parameters_kr16_2.yaml states as OPW a2=+0.035, so the FreeCAD
    # a=+45 of the KR 125 is OPW a2=-0.045 (wrist point 45 mm above A3 at home).
    a1=0.410,
    a2=-0.045,
    b=0.0,
    c1=0.865,
    c2=1.000,
    c3=1.000,
    c4=0.210,
    offsets_deg=KUKA_OFFSETS_DEG,
    sign_corrections=KUKA_SIGNS,
    # FreeCAD kr_125.csv: A1 +-185, A2 -130..+3, A3 -120..+148, A4 +-350, A5 +-120, A6 +-350 deg;
    # speeds 100, 100, 100, 154, 167, 251 deg/s.
    lower_deg=(-185.0, -130.0, -120.0, -350.0, -120.0, -350.0),
    upper_deg=(185.0, 3.0, 148.0, 350.0, 120.0, 350.0),
    velocity_deg_s=(100.0, 100.0, 100.0, 154.0, 167.0, 251.0),
    effort_nm=(9000.0, 9000.0, 4500.0, 900.0, 900.0, 500.0),  # estimated
    acceleration_deg_s2=(200.0, 200.0, 200.0, 380.0, 420.0, 630.0),  # estimated
    jerk_deg_s3=(2000.0, 2000.0, 2000.0, 3800.0, 4200.0, 6300.0),  # estimated
    masses_kg=(190.0, 330.0, 170.0, 145.0, 60.0, 22.0, 6.0),  # estimated
    width=1.0,
    base_height=0.30,
    a4_bearing=0.20,
    flange_radius=0.08,
    flange_thickness=0.03,
    counterbalance=True,
    yaml_header=(
        "# KUKA KR 125/2-class six-axis spot-welding arm (the class used in the published ROBOMAX\n"
        "# welding cells): 125 kg payload, 2.41 m reach to the wrist point.\n"
        "# Generated by robots/generate.py -- edit the script, not this file.\n"
    ),
    params_comment=(
        "    # Lengths from the public KR 125 DH table of the FreeCAD Robot workbench\n"
        "    # (src/Mod/Robot/Lib/Kuka/kr_125.csv: 410/865, 1000, 45, 1000, 210 mm);\n"
        "    # a1 + c2 + c3 = 2.41 m, the KR 125/2 reach. a2 sign: FreeCAD's +45 mm maps to OPW -0.045\n"
        "    # by the same table's KR 16 (-35 mm), which ROS-Industrial kuka_experimental\n"
        "    # (kuka_kr16_support/config/opw_parameters_kr16_2.yaml) gives as OPW a2 = +0.035.\n"
        "    # KUKA joint convention (A1 and A4/A6 counted the other way, A2 = -90 deg with the link\n"
        "    # arm vertical), as in opw_kinematics' makeKukaKR6_R700_sixx.\n"
    ),
    limits_comment=(
        "  # estimated: no public data sheet gives the KR 125/2's accelerations or jerks; values take\n"
        "  # roughly 0.5 s (main axes) / 0.4 s (wrist) to reach the data-sheet speeds, jerk = 10 x acc.\n"
    ),
    urdf_comment=(
        "Joint position limits and speeds: FreeCAD Robot workbench kr_125.csv (public KR 125 data). "
        "Masses, inertias and efforts are estimated (total about 930 kg for a KR 125/2-class arm). "
        "Meshes are generated look-alikes, not KUKA CAD."
    ),
)

KR16 = ArmData(
    name="kr16",
    title="KUKA KR 16-2-class six-axis arm (reach 1.61 m to the wrist point)",
    payload_kg=16.0,
    # ROS-Industrial kuka_experimental: kuka_kr16_support/urdf/kr16_2_macro.xacro and
    # config/opw_parameters_kr16_2.yaml; FreeCAD src/Mod/Robot/Lib/Kuka/kr_16.csv agrees.
    a1=0.260,
    a2=0.035,
    b=0.0,
    c1=0.675,
    c2=0.680,
    c3=0.670,
    c4=0.158,
    offsets_deg=KUKA_OFFSETS_DEG,
    sign_corrections=KUKA_SIGNS,
    # kr16_2_macro.xacro and kr_16.csv: A1 +-185 156, A2 -155..+35 156, A3 -130..+154 156,
    # A4 +-350 330, A5 +-130 330, A6 +-350 615 (deg, deg/s).
    lower_deg=(-185.0, -155.0, -130.0, -350.0, -130.0, -350.0),
    upper_deg=(185.0, 35.0, 154.0, 350.0, 130.0, 350.0),
    velocity_deg_s=(156.0, 156.0, 156.0, 330.0, 330.0, 615.0),
    effort_nm=(1500.0, 1500.0, 800.0, 120.0, 120.0, 60.0),  # estimated
    acceleration_deg_s2=(520.0, 520.0, 520.0, 1100.0, 1100.0, 2050.0),  # estimated
    jerk_deg_s3=(5200.0, 5200.0, 5200.0, 11000.0, 11000.0, 20500.0),  # estimated
    masses_kg=(48.0, 80.0, 45.0, 35.0, 16.0, 6.0, 1.0),  # estimated (sum ~ 231 kg)
    width=0.55,
    base_height=0.20,
    a4_bearing=0.12,
    flange_radius=0.045,
    flange_thickness=0.02,
    counterbalance=False,
    yaml_header=(
        "# KUKA KR 16-2-class six-axis arm: 16 kg payload, 1.61 m reach to the wrist point.\n"
        "# Generated by robots/generate.py -- edit the script, not this file.\n"
    ),
    params_comment=(
        "    # ROS-Industrial kuka_experimental, kuka_kr16_support/config/opw_parameters_kr16_2.yaml\n"
        "    # and urdf/kr16_2_macro.xacro (A4 35 mm below A3 at home, so OPW a2 = +0.035, not -0.035);\n"
        "    # FreeCAD src/Mod/Robot/Lib/Kuka/kr_16.csv gives the same lengths.\n"
    ),
    limits_comment=(
        "  # estimated: the data sheet gives no accelerations or jerks; values reach the data-sheet\n"
        "  # speeds in about 0.3 s, jerk = 10 x acc.\n"
    ),
    urdf_comment=(
        "Joint limits and speeds: ROS-Industrial kuka_experimental kr16_2_macro.xacro and FreeCAD "
        "kr_16.csv. Masses (about 230 kg in all), inertias and efforts are estimated. "
        "Meshes are generated look-alikes, not KUKA CAD."
    ),
    # Our estimate: KUKA publishes no payload-dependent limits (its controller derives them from
    # the load data); full speed, 60 % of the acceleration and jerk with 16 kg at the flange.
    loaded_scale=(1.0, 0.6, 0.6),
)

ARMS = (KR125, KR16)
LINKS = ("base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6")


# ----------------------------------------------------------------------------------------------
# Gun data
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class GunData:
    """Key dimensions of the C-type servo spot-welding gun, m.

    The gun is drawn in its own frame G (z = electrode closing axis, the C-back along +y) and hung
    from the robot flange by a bracket on top of the C-back, so that the electrode axis is
    perpendicular to the flange axis, as on most robot C-guns: at a spot the wrist sits above and
    behind the gun instead of in line with the electrodes, which keeps a 2.4 m arm out of its
    folded-elbow limit when welding at 1.3-1.4 m reach.
    """

    tcp_z: float = 0.50  # fixed-electrode tip face = TCP, on G's z axis
    gap: float = 0.07  # open stroke between the tips, >= 0.06 for a 30 mm approach either side
    throat: float = 0.16  # electrode axis to the inside of the C back, along +y, >= 0.12
    back_thickness: float = 0.05
    c_width: float = 0.05  # C-frame plate width along x
    electrode_radius: float = 0.008  # 16 mm shank
    mount_y: float = 0.27  # flange face above the electrode axis (G y): back top + 60 mm bracket
    mount_z: float = 0.30  # flange centre along the electrode axis (G z), near the centre of mass


GUN = GunData()


# ----------------------------------------------------------------------------------------------
# Mesh primitives (each returns one closed, consistently wound shell)
# ----------------------------------------------------------------------------------------------


def _unit(v: FloatArray) -> FloatArray:
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        raise ValueError("zero-length direction")
    return np.asarray(v, dtype=float) / n


def _perp_frame(axis: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Two unit vectors completing ``axis`` to a right-handed frame, chosen deterministically."""
    u = _unit(axis)
    ref = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = _unit(ref - np.dot(ref, u) * u)
    e2 = np.cross(u, e1)
    return e1, e2


def _tube(rings: Sequence[FloatArray]) -> trimesh.Trimesh:
    """Closed mesh through ``k >= 2`` rings of ``m`` points each; the end rings are capped.

    Parameters
    ----------
    rings : sequence of (m, 3) float
        Points of each ring in the same angular order, metres.
    """
    k = len(rings)
    m = len(rings[0])
    verts = np.vstack([np.asarray(r, dtype=float) for r in rings] + [rings[0].mean(0), rings[-1].mean(0)])
    faces: list[tuple[int, int, int]] = []
    for i in range(k - 1):
        for j in range(m):
            a, b = i * m + j, i * m + (j + 1) % m
            c, d = (i + 1) * m + (j + 1) % m, (i + 1) * m + j
            faces += [(a, b, c), (a, c, d)]
    c0, c1 = k * m, k * m + 1
    for j in range(m):
        faces.append((c0, (j + 1) % m, j))
        top = (k - 1) * m
        faces.append((c1, top + j, top + (j + 1) % m))
    mesh = trimesh.Trimesh(verts, np.asarray(faces, dtype=np.int64), process=False)
    if mesh.volume < 0.0:  # rings were clockwise about the tube direction: flip every face
        mesh = trimesh.Trimesh(verts, np.asarray(faces, dtype=np.int64)[:, ::-1], process=False)
    if not (mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0.0):
        raise RuntimeError("tube shell came out open or inside out")
    return mesh


def _circle(n: int = CIRCLE_SEGMENTS) -> FloatArray:
    t = 2.0 * np.pi * np.arange(n) / n
    return np.column_stack([np.cos(t), np.sin(t)])


def _rounded_rect(w: float, h: float, r: float) -> FloatArray:
    """Outline (4*(CORNER_SEGMENTS+1), 2) of a w x h rectangle with corner radius r, centred."""
    r = min(r, 0.5 * w - 1e-6, 0.5 * h - 1e-6)
    pts = []
    corners = ((0.5 * w - r, 0.5 * h - r, 0.0), (-0.5 * w + r, 0.5 * h - r, 0.5 * np.pi),
               (-0.5 * w + r, -0.5 * h + r, np.pi), (0.5 * w - r, -0.5 * h + r, 1.5 * np.pi))
    for cx, cy, a0 in corners:
        for t in a0 + 0.5 * np.pi * np.arange(CORNER_SEGMENTS + 1) / CORNER_SEGMENTS:
            pts.append((cx + r * math.cos(t), cy + r * math.sin(t)))
    return np.asarray(pts)


def cylinder(p0: Point, p1: Point, r0: float, r1: float | None = None,
             n: int = CIRCLE_SEGMENTS) -> trimesh.Trimesh:
    """Cylinder (or cone frustum if ``r1`` differs) from ``p0`` to ``p1``; convex."""
    a, b = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    e1, e2 = _perp_frame(b - a)
    c = _circle(n)
    ring = c[:, :1] * e1 + c[:, 1:] * e2
    return _tube([a + r0 * ring, b + (r0 if r1 is None else r1) * ring])


def loft_z(sections: Sequence[tuple[float, float, float, float, float, float]]) -> trimesh.Trimesh:
    """Loft of rounded rectangles stacked along z: the tapered, rounded look of a cast link.

    Parameters
    ----------
    sections : sequence of (z, cx, cy, wx, wy, corner_radius)
        One rounded rectangle per z level, metres.
    """
    rings = []
    for z, cx, cy, wx, wy, r in sections:
        o = _rounded_rect(wx, wy, r)
        rings.append(np.column_stack([o[:, 0] + cx, o[:, 1] + cy, np.full(len(o), z)]))
    return _tube(rings)


def box(lo: Point, hi: Point) -> trimesh.Trimesh:
    """Axis-aligned box between corners ``lo`` and ``hi``; convex."""
    lo_a, hi_a = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    m = trimesh.creation.box(extents=hi_a - lo_a)
    return trimesh.Trimesh(m.vertices + 0.5 * (lo_a + hi_a), m.faces, process=False)


# ----------------------------------------------------------------------------------------------
# Arm geometry, modelled in the OPW zero pose (arm straight up, all link frames parallel to base)
# ----------------------------------------------------------------------------------------------


@dataclass(slots=True)
class _LinkShapes:
    """Visual shells of one link and the collision group each belongs to."""

    shells: list[trimesh.Trimesh] = field(default_factory=list)
    groups: list[int] = field(default_factory=list)

    def add(self, group: int, *meshes: trimesh.Trimesh) -> None:
        for m in meshes:
            self.shells.append(m)
            self.groups.append(group)


def _motor(p0: FloatArray, axis: FloatArray, length: float, r: float) -> list[trimesh.Trimesh]:
    """A servo motor: body with cooling ribs, a smaller end cap and a connector box."""
    u = _unit(axis)
    p0 = np.asarray(p0, dtype=float)
    parts = [cylinder(p0, p0 + 0.82 * length * u, r)]
    for f in (0.2, 0.38, 0.56):  # ribs, slightly proud of the body
        parts.append(cylinder(p0 + f * length * u, p0 + (f + 0.05) * length * u, 1.08 * r))
    parts.append(cylinder(p0 + 0.8 * length * u, p0 + length * u, 0.8 * r, 0.72 * r))
    e1, _ = _perp_frame(u)
    c = p0 + 0.5 * length * u + 0.95 * r * e1
    half = 0.3 * r
    parts.append(box(c - half, c + half))
    return parts


def _arm_shapes(arm: ArmData) -> dict[str, _LinkShapes]:
    """Visual shells of every link, in the zero-pose base frame."""
    w = arm.width
    a1, a2, c1, c2, c3, c4 = arm.a1, arm.a2, arm.c1, arm.c2, arm.c3, arm.c4
    zb = arm.base_height
    # Mid-plane of the link arm, beside the column (KUKA arms are one-sided). Far enough out that the
    # forearm (radius <= 0.145 w about y = 0) folds past the link arm's inner face (-0.165 w).
    y_l = -0.25 * w
    z3 = c1 + c2  # A3 height in the zero pose
    x_f = a1 + a2  # forearm (A4) axis
    z_w = z3 + c3  # wrist point
    shapes = {name: _LinkShapes() for name in LINKS}

    # base_link: foot plate, cast base frame, cable connector box at the rear.
    s = shapes["base_link"]
    s.add(0, loft_z([(0.0, 0.0, 0.0, 0.86 * w, 0.86 * w, 0.08 * w),
                     (0.045 * w, 0.0, 0.0, 0.86 * w, 0.86 * w, 0.08 * w)]))
    s.add(1, cylinder((0, 0, 0.04 * w), (0, 0, zb - 0.06 * w), 0.40 * w, 0.33 * w),
          cylinder((0, 0, zb - 0.065 * w), (0, 0, zb), 0.35 * w))
    s.add(2, loft_z([(0.04 * w, -0.38 * w, 0.0, 0.16 * w, 0.26 * w, 0.03 * w),
                     (0.20 * w, -0.38 * w, 0.0, 0.16 * w, 0.26 * w, 0.03 * w)]))

    # link_1: turntable, rotating column carrying the A2 gearbox, A1 and A2 motors and
    # (KR 125) the counterbalance pivot behind A2.
    s = shapes["link_1"]
    s.add(0, cylinder((0, 0, zb), (0, 0, zb + 0.10 * w), 0.37 * w))
    col_y, col_w = 0.07 * w, 0.34 * w  # column spans y in [-0.10, 0.24] w: the link arm is at -y
    s.add(1, loft_z([(zb + 0.09 * w, 0.02 * w, col_y, 0.66 * w, col_w + 0.02 * w, 0.12 * w),
                     (0.5 * (zb + c1), 0.5 * (0.02 * w + a1 - 0.06 * w), col_y, 0.52 * w, col_w, 0.10 * w),
                     (c1, a1 - 0.06 * w, col_y, 0.42 * w, col_w, 0.08 * w)]),
          cylinder((a1, y_l + 0.09 * w, c1), (a1, col_y + 0.5 * col_w, c1), 0.22 * w))
    s.add(1, *_motor(np.array([-0.24 * w, 0.17 * w, zb + 0.10 * w]), np.array([0.0, 0.0, 1.0]),
                     0.34 * w, 0.075 * w))
    s.add(2, *_motor(np.array([a1 - 0.12 * w, col_y + 0.5 * col_w - 0.01 * w, c1 + 0.02 * w]),
                     np.array([0.0, 1.0, 0.0]), 0.26 * w, 0.085 * w))
    if arm.counterbalance:
        # Hydro-pneumatic counterbalance from a pivot on the column's rear to an eye on the link
        # arm; modelled rigid with the column (its real swing is small near home).
        pivot = np.array([-0.27 * w, y_l, c1 - 0.02 * w])
        eye = np.array([a1 - 0.22 * w, y_l, c1 + 0.26 * w])
        d = _unit(eye - pivot)
        length = float(np.linalg.norm(eye - pivot))
        s.add(3, box((-0.36 * w, y_l - 0.07 * w, c1 - 0.11 * w), (-0.17 * w, -0.06 * w, c1 + 0.06 * w)),
              cylinder(pivot - 0.06 * w * d, pivot + 0.62 * length * d, 0.085 * w),
              cylinder(pivot + 0.62 * length * d, eye, 0.035 * w),
              cylinder(eye - 0.02 * w * np.array([0, 1, 0]), eye + 0.02 * w * np.array([0, 1, 0]), 0.045 * w))

    # link_2: the link arm, a waisted cast beam with round hubs at A2 and A3.
    s = shapes["link_2"]
    t2 = 0.085 * w  # half thickness along y
    s.add(0, cylinder((a1, y_l - t2, c1), (a1, y_l + t2, c1), 0.21 * w),
          cylinder((a1, y_l - 0.9 * t2, z3), (a1, y_l + 0.9 * t2, z3), 0.16 * w),
          loft_z([(c1, a1, y_l, 0.38 * w, 2 * t2, 0.06 * w),
                  (c1 + 0.35 * c2, a1, y_l, 0.30 * w, 1.9 * t2, 0.06 * w),
                  (c1 + 0.75 * c2, a1, y_l, 0.27 * w, 1.8 * t2, 0.06 * w),
                  (z3, a1, y_l, 0.28 * w, 1.8 * t2, 0.06 * w)]))
    if arm.counterbalance:
        s.add(1, box((a1 - 0.25 * w, y_l - 0.05 * w, c1 + 0.21 * w), (a1 - 0.15 * w, y_l + 0.05 * w, c1 + 0.31 * w)))

    # link_3: A3 gearbox beside the link arm, the arm's rear housing and the three wrist motors
    # behind A3 (below it in the zero pose, behind it at home), as on KUKA arms.
    s = shapes["link_3"]
    y_in = y_l + t2 + 0.005 * w  # inner face of the link arm
    s.add(0, cylinder((a1, y_in, z3), (a1, 0.15 * w, z3), 0.17 * w))
    hy0, hy1 = y_in + 0.005 * w, 0.155 * w
    hc, hw = 0.5 * (hy0 + hy1), hy1 - hy0
    s.add(1, loft_z([(z3 - 0.36 * w, x_f, hc, 0.28 * w, hw - 0.02 * w, 0.06 * w),
                     (z3 - 0.05 * w, x_f, hc, 0.34 * w, hw, 0.08 * w),
                     (z3 + arm.a4_bearing, x_f, hc, 0.30 * w, hw - 0.01 * w, 0.08 * w)]))
    for dx, dy in ((0.075 * w, 0.085 * w), (-0.075 * w, 0.085 * w), (0.0, -0.035 * w)):
        s.add(2, *_motor(np.array([x_f + dx, dy, z3 - 0.35 * w]), np.array([0.0, 0.0, -1.0]),
                         0.22 * w, 0.052 * w))

    # link_4: A4 bearing, forearm tube and the wrist fork around A5.
    s = shapes["link_4"]
    z4 = z3 + arm.a4_bearing
    s.add(0, cylinder((x_f, 0, z4), (x_f, 0, z4 + 0.05 * w), 0.145 * w),
          cylinder((x_f, 0, z4 + 0.04 * w), (x_f, 0, z_w - 0.20 * w), 0.13 * w, 0.105 * w))
    s.add(1, loft_z([(z_w - 0.25 * w, x_f, 0.0, 0.22 * w, 0.30 * w, 0.05 * w),
                     (z_w - 0.12 * w, x_f, 0.0, 0.22 * w, 0.30 * w, 0.05 * w)]))
    for sgn in (1.0, -1.0):
        y0, y1 = sgn * 0.085 * w, sgn * 0.15 * w
        s.add(1, box((x_f - 0.11 * w, min(y0, y1), z_w - 0.14 * w), (x_f + 0.11 * w, max(y0, y1), z_w)),
              cylinder((x_f, y0, z_w), (x_f, y1, z_w), 0.11 * w))

    # link_5: wrist body between the fork cheeks and the A6 neck up to the flange.
    s = shapes["link_5"]
    z6 = z_w + c4 - arm.flange_thickness  # A6 joint origin: back face of the flange
    s.add(0, cylinder((x_f, -0.08 * w, z_w), (x_f, 0.08 * w, z_w), 0.095 * w),
          cylinder((x_f, 0, z_w), (x_f, 0, z6 - 0.004 * w), 0.082 * w),
          cylinder((x_f, 0, z6 - 0.05 * w), (x_f, 0, z6 - 0.004 * w), 0.09 * w))

    # link_6: the mounting flange (ISO 9409-1 style disc), its face is tool0.
    s = shapes["link_6"]
    s.add(0, cylinder((x_f, 0, z6), (x_f, 0, z_w + c4), arm.flange_radius),
          cylinder((x_f, 0, z6 - 0.002), (x_f, 0, z6 + 0.4 * arm.flange_thickness), 0.75 * arm.flange_radius))
    return shapes


def _link_origins(arm: ArmData) -> dict[str, FloatArray]:
    """Origin of each link frame in the zero-pose base frame, m (all frames parallel to base)."""
    y_l = -0.25 * arm.width
    z3 = arm.c1 + arm.c2
    x_f = arm.a1 + arm.a2
    z_w = z3 + arm.c3
    return {
        "base_link": np.zeros(3),
        "link_1": np.array([0.0, 0.0, arm.base_height]),
        "link_2": np.array([arm.a1, arm.b + y_l, arm.c1]),
        "link_3": np.array([arm.a1, arm.b + y_l, z3]),
        "link_4": np.array([x_f, arm.b, z3 + arm.a4_bearing]),
        "link_5": np.array([x_f, arm.b, z_w]),
        "link_6": np.array([x_f, arm.b, z_w + arm.c4 - arm.flange_thickness]),
        "tool0": np.array([x_f, arm.b, z_w + arm.c4]),
    }


# ----------------------------------------------------------------------------------------------
# Gun geometry, drawn in the gun frame G (z = closing axis, TCP at (0, 0, tcp_z)), then mounted
# ----------------------------------------------------------------------------------------------


def _gun_shells(g: GunData) -> tuple[list[trimesh.Trimesh], list[trimesh.Trimesh]]:
    """Convex shells of the gun body and of the electrode tips.

    Layout (gun frame G): transformer and servo actuator in line with the moving electrode (+z),
    a C-frame whose back runs parallel to z at ``y = throat`` (so it passes over the panel
    flange's top edge), a jaw at the far end holding the fixed electrode, cranked up so the jaw
    stays clear of the panel, and the mounting bracket on top of the C-back. Returned in the
    flange frame (see `gun_mount`).
    """
    z_tcp, re = g.tcp_z, g.electrode_radius
    z_mov = z_tcp - g.gap  # moving tip face
    hw = 0.5 * g.c_width
    y_back0, y_back1 = g.throat, g.throat + g.back_thickness
    body = [
        # Insulated adapter plate on the bracket, 2 mm off the flange face so mounting is not a
        # contact, and the bracket down to the C-back.
        cylinder((0, g.mount_y - 0.002, g.mount_z), (0, g.mount_y - 0.03, g.mount_z), 0.09),
        box((-0.06, y_back1 - 0.005, g.mount_z - 0.09), (0.06, g.mount_y - 0.029, g.mount_z + 0.09)),
        # Weld transformer housing (medium-frequency DC type), straddling the axis.
        box((-0.085, -0.115, 0.029), (0.085, 0.095, 0.19)),
        # Servo motor and spindle housing on the electrode axis.
        cylinder((0, 0, 0.188), (0, 0, 0.30), 0.06),
        cylinder((0, 0, 0.295), (0, 0, z_mov - 0.085), 0.042, 0.036),
        # Moving electrode holder (water-cooled arm end), in line with the spindle.
        cylinder((0, 0, z_mov - 0.09), (0, 0, z_mov - 0.033), 0.02),
        # C-frame: lower arm from the transformer up to the back, the back, and the upper jaw.
        box((-hw, 0.09, 0.12), (hw, y_back1, 0.19)),
        box((-hw, y_back0, 0.185), (hw, y_back1, z_tcp + 0.085)),
        box((-0.5 * hw, 0.075, z_tcp + 0.04), (0.5 * hw, y_back0 + 0.005, z_tcp + 0.085)),
        # Fixed electrode holder block at the jaw's lower end.
        box((-0.017, 0.034, z_tcp + 0.035), (0.017, 0.08, z_tcp + 0.07)),
    ]
    # Fixed electrode: cap and an 18 mm straight shank on the axis, then cranked up by about 50 deg
    # into the holder, so the jaw hangs no lower than y = +34 mm: about 50 mm above the reference
    # panel's sheet behind its flange, which +-10 deg tilts raise by at most ~15 mm there.
    crank0 = np.array([0.0, 0.0, z_tcp + 0.018])
    crank1 = np.array([0.0, 0.045, z_tcp + 0.055])
    tips = [
        cylinder((0, 0, z_mov - 0.006), (0, 0, z_mov), re, 0.0045),  # moving cap, face at z_mov
        cylinder((0, 0, z_mov - 0.04), (0, 0, z_mov - 0.0055), re),  # moving shank
        cylinder((0, 0, z_tcp + 0.006), (0, 0, z_tcp), re, 0.0045),  # fixed cap, face at TCP
        cylinder((0, 0, z_tcp + 0.0055), crank0 + np.array([0, 0, 0.004]), re),  # fixed shank
        cylinder(crank0 - 0.003 * _unit(crank1 - crank0), crank1, re),  # cranked part
    ]
    T_flange_gun = np.linalg.inv(gun_mount(g))
    return [m.apply_transform(T_flange_gun) for m in body], [m.apply_transform(T_flange_gun) for m in tips]


def gun_mount(g: GunData) -> FloatArray:
    """T_gun_flange: the flange frame in the gun frame G.

    Flange z points from the bracket into the gun (-G y); flange x runs along the closing axis
    (+G z), so TCP z = flange x and TCP y (towards the C-back) = -flange z.
    """
    T = np.eye(4)
    T[:3, 0] = (0.0, 0.0, 1.0)
    T[:3, 1] = (-1.0, 0.0, 0.0)
    T[:3, 2] = (0.0, -1.0, 0.0)
    T[:3, 3] = (0.0, g.mount_y, g.mount_z)
    return T


def gun_tcp(g: GunData) -> FloatArray:
    """T_flange_tcp of the mounted gun."""
    T_gun_tcp = np.eye(4)
    T_gun_tcp[2, 3] = g.tcp_z
    return np.linalg.inv(gun_mount(g)) @ T_gun_tcp


# ----------------------------------------------------------------------------------------------
# Writers
# ----------------------------------------------------------------------------------------------


def _f(x: float) -> str:
    """Text of a float to 15 significant digits: folds sums like 0.865 - 0.3 back to 0.565 but
    keeps angles such as pi/2 to ~1e-15 rad, far below the 1e-12 FK agreement the tests ask."""
    v = float(f"{float(x):.15g}")
    if v == 0.0:
        return "0"
    return str(int(v)) if v.is_integer() and abs(v) < 1e6 else repr(v)


def _stl_bytes(mesh: trimesh.Trimesh) -> bytes:
    """Binary STL with a fixed header (no timestamps), so reruns are byte-identical."""
    tris = np.asarray(mesh.vertices, dtype=np.float64)[np.asarray(mesh.faces)]
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, norm, out=np.zeros_like(n), where=norm > 0)
    rec = np.zeros(len(tris), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"] = n
    rec["v"] = tris
    header = b"robomax_py robots/generate.py binary STL, metres".ljust(80, b" ")
    return header + struct.pack("<I", len(tris)) + rec.tobytes()


def _f32(points: FloatArray) -> FloatArray:
    """Round to float32, the precision STL stores, so hulls are computed on the stored points."""
    return np.asarray(points, dtype=np.float32).astype(np.float64)


def _hull(points: FloatArray) -> trimesh.Trimesh:
    hull: trimesh.Trimesh = trimesh.convex.convex_hull(_f32(points))
    if not (hull.is_watertight and hull.is_convex):
        raise RuntimeError("convex hull came out open or non-convex")
    return hull


def _concat(meshes: Sequence[trimesh.Trimesh], offset: FloatArray) -> trimesh.Trimesh:
    verts, faces, n = [], [], 0
    for m in meshes:
        verts.append(np.asarray(m.vertices) - offset)
        faces.append(np.asarray(m.faces) + n)
        n += len(m.vertices)
    return trimesh.Trimesh(_f32(np.vstack(verts)), np.vstack(faces), process=False)


def _inertial_xml(hull: trimesh.Trimesh, mass: float) -> str:
    """<inertial> of a solid of the hull's shape with the given mass (estimated)."""
    com = hull.center_mass
    inertia = hull.moment_inertia * (mass / hull.volume)
    i = inertia
    return (
        "    <inertial>\n"
        f"      <origin xyz=\"{_g(com[0])} {_g(com[1])} {_g(com[2])}\" rpy=\"0 0 0\"/>\n"
        f"      <mass value=\"{_g(mass)}\"/>\n"
        f"      <inertia ixx=\"{_g(i[0, 0])}\" ixy=\"{_g(i[0, 1])}\" ixz=\"{_g(i[0, 2])}\" "
        f"iyy=\"{_g(i[1, 1])}\" iyz=\"{_g(i[1, 2])}\" izz=\"{_g(i[2, 2])}\"/>\n"
        "    </inertial>\n"
    )


def _g(x: float) -> str:
    """Six significant digits: enough for estimated inertial data, stable across reruns."""
    v = float(f"{float(x):.6g}")
    return "0" if abs(v) < 1e-9 else f"{v:.6g}"


@dataclass(frozen=True, slots=True)
class _Joint:
    name: str
    parent: str
    child: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float] | None  # None: fixed joint


def _vec3(v: Sequence[float] | FloatArray) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _joints(arm: ArmData) -> list[_Joint]:
    """Joint origins from the OPW parameters (see the module docstring)."""
    o = _link_origins(arm)
    off = [math.radians(v) for v in arm.offsets_deg]
    s = arm.sign_corrections
    # Axis of each joint in its link frame: A1, A4, A6 about z; A2, A3, A5 about y.
    unit = ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    chain = list(LINKS)
    joints = []
    for i in range(6):
        parent, child = chain[i], chain[i + 1]
        xyz = o[child] - o[parent]
        # A fixed rotation by -offset about the joint axis turns sign*q into the paper angle.
        rpy = (0.0, -off[i], 0.0) if unit[i][1] else (0.0, 0.0, -off[i])
        axis = [float(s[i] * c) for c in unit[i]]
        joints.append(_Joint(f"joint_a{i + 1}", parent, child, _vec3(xyz), rpy, _vec3(axis)))
    xyz = o["tool0"] - o["link_6"]
    joints.append(_Joint("joint_a6-tool0", "link_6", "tool0", _vec3(xyz), (0.0, 0.0, 0.0), None))
    return joints


def _urdf(arm: ArmData, n_collision: dict[str, int], hulls: dict[str, trimesh.Trimesh]) -> str:
    lines = [
        '<?xml version="1.0"?>\n',
        f"<!-- {arm.title}.\n",
        "     Generated by robots/generate.py from the OPW parameters in robot.yaml; do not edit.\n",
        f"     {arm.urdf_comment}\n",
        "     Link frames are the OPW paper's frames (z up along the arm at theta = 0); joint values\n",
        "     are KUKA axis angles: theta = q * sign_correction - offset. tool0 = $FLANGE, z out. -->\n",
        f'<robot name="{arm.name}">\n',
    ]
    for k, link in enumerate(LINKS):
        lines.append(f'  <link name="{link}">\n')
        lines.append(_inertial_xml(hulls[link], arm.masses_kg[k]))
        lines.append(
            "    <visual>\n      <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n"
            f"      <geometry><mesh filename=\"meshes/visual/{link}.stl\"/></geometry>\n    </visual>\n"
        )
        for j in range(n_collision[link]):
            lines.append(
                "    <collision>\n      <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n"
                f"      <geometry><mesh filename=\"meshes/collision/{link}_{j}.stl\"/></geometry>\n"
                "    </collision>\n"
            )
        lines.append("  </link>\n")
    lines.append('  <link name="tool0"/>\n')
    for i, jt in enumerate(_joints(arm)):
        kind = "fixed" if jt.axis is None else "revolute"
        lines.append(f'  <joint name="{jt.name}" type="{kind}">\n')
        lines.append(f'    <parent link="{jt.parent}"/>\n    <child link="{jt.child}"/>\n')
        lines.append(f'    <origin xyz="{" ".join(_f(v) for v in jt.xyz)}" rpy="{" ".join(_f(v) for v in jt.rpy)}"/>\n')
        if jt.axis is not None:
            lines.append(f'    <axis xyz="{" ".join(_f(v) for v in jt.axis)}"/>\n')
            lines.append(
                f'    <limit lower="{_f(math.radians(arm.lower_deg[i]))}" upper="{_f(math.radians(arm.upper_deg[i]))}" '
                f'velocity="{_f(math.radians(arm.velocity_deg_s[i]))}" effort="{_f(arm.effort_nm[i])}"/>\n'
            )
        lines.append("  </joint>\n")
    lines.append("</robot>\n")
    return "".join(lines)


def _robot_yaml(arm: ArmData) -> str:
    return (
        arm.yaml_header
        + f"name: {arm.name}\n"
        + f"payload: {arm.payload_kg:g}\n"
        + f"description: {arm.title}\n"
        + f"urdf: {arm.name}.urdf\n"
        + "flange: tool0\n"
        + "ik:\n"
        + "  solver: opw\n"
        + "  params:\n"
        + arm.params_comment
        + f"    a1: {arm.a1:g}\n    a2: {arm.a2:g}\n    b: {arm.b:g}\n"
        + f"    c1: {arm.c1:g}\n    c2: {arm.c2:g}\n    c3: {arm.c3:g}\n    c4: {arm.c4:g}\n"
        + f"    offsets: {_yaml_list(arm.offsets_deg)}\n"
        + f"    sign_corrections: {_yaml_list(arm.sign_corrections)}\n"
        + "limits:\n"
        + arm.limits_comment
        + f"  acceleration: {_yaml_list(arm.acceleration_deg_s2)}   # deg/s^2, estimated\n"
        + f"  jerk: {_yaml_list(arm.jerk_deg_s3)}   # deg/s^3, estimated\n"
        + _loaded_yaml(arm)
    )


def _yaml_list(v: Sequence[float]) -> str:
    return "[" + ", ".join(f"{x:g}" for x in v) + "]"


def _loaded_yaml(arm: ArmData) -> str:
    if arm.loaded_scale is None:
        return ""
    v, a, j = arm.loaded_scale
    return (
        f"  # estimated: with the rated {arm.payload_kg:g} kg payload, {v:.0%} of the speeds, {a:.0%} of the\n"
        f"  # accelerations and {j:.0%} of the jerks (lighter parts: in proportion to their mass)\n"
        + "  loaded:\n"
        + f"    velocity: {_yaml_list(tuple(v * x for x in arm.velocity_deg_s))}   # deg/s\n"
        + f"    acceleration: {_yaml_list(tuple(a * x for x in arm.acceleration_deg_s2))}   # deg/s^2\n"
        + f"    jerk: {_yaml_list(tuple(j * x for x in arm.jerk_deg_s3))}   # deg/s^3\n"
    )


def _tool_yaml(g: GunData) -> str:
    T = gun_tcp(g)
    # rpy [-90, 0, -90] deg is Rz(-90) Rx(-90): TCP x = -flange y, y = -flange z, z = flange x.
    expected = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    if not np.allclose(T[:3, :3], expected, atol=1e-12):
        raise RuntimeError("gun mount no longer matches the TCP rpy written to tool.yaml")
    xyz = T[:3, 3]
    return (
        "# C-type servo spot-welding gun (generic, generated look-alike; dimensions estimated from\n"
        "# typical 100-150 kg class servo C-guns). Generated by robots/generate.py -- do not edit.\n"
        f"# Throat depth (electrode axis to the inside of the C back, along +y): {g.throat:g} m.\n"
        f"# Open gap between the moving and the fixed tip: {g.gap:g} m. Electrodes 16 mm diameter.\n"
        "# Hung from the flange by a bracket on the C-back: the electrode axis is perpendicular to\n"
        "# the flange axis, the TCP sits below and in front of the flange.\n"
        "# body.stl and tips.stl are unions of separate convex shells (split() recovers them).\n"
        "name: spot_gun_c\n"
        "body: body.stl\n"
        "tips: tips.stl\n"
        f"tcp: {{xyz: [{_g(xyz[0])}, {_g(xyz[1])}, {_g(xyz[2])}], rpy: [-90, 0, -90]}}"
        "   # fixed-tip face; z = closing axis = flange x\n"
    )


def _shells_mesh(shells: Sequence[trimesh.Trimesh]) -> trimesh.Trimesh:
    """One mesh of separate shells, each vertex-rounded to float32 as STL will store it."""
    mesh = _concat(shells, np.zeros(3))
    # split() of the stored file must give back exactly these shells: no two may share a vertex.
    pieces = trimesh.Trimesh(mesh.vertices, mesh.faces, process=True).split(only_watertight=False)
    if len(pieces) != len(shells):
        raise RuntimeError(f"{len(shells)} shells merged into {len(pieces)} pieces")
    return mesh


def generate(out: Path) -> list[Path]:
    """Write every generated file under ``out`` (the ``robots/`` folder layout).

    Returns
    -------
    list of Path
        The files written, in a fixed order.
    """
    written: list[Path] = []

    def put(path: Path, data: bytes) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
        written.append(path)

    for arm in ARMS:
        root = out / arm.name
        shapes = _arm_shapes(arm)
        origins = _link_origins(arm)
        n_collision: dict[str, int] = {}
        link_hulls: dict[str, trimesh.Trimesh] = {}
        for link in LINKS:
            sh = shapes[link]
            visual = _concat(sh.shells, origins[link])
            put(root / "meshes" / "visual" / f"{link}.stl", _stl_bytes(visual))
            groups = sorted(set(sh.groups))
            n_collision[link] = len(groups)
            for j, grp in enumerate(groups):
                pts = np.vstack([m.vertices for m, g in zip(sh.shells, sh.groups) if g == grp]) - origins[link]
                put(root / "meshes" / "collision" / f"{link}_{j}.stl", _stl_bytes(_hull(pts)))
            link_hulls[link] = _hull(np.asarray(visual.vertices))
        put(root / f"{arm.name}.urdf", _urdf(arm, n_collision, link_hulls).encode())
        put(root / "robot.yaml", _robot_yaml(arm).encode())

    gun_root = out / "tools" / "spot_gun_c"
    body, tips = _gun_shells(GUN)
    put(gun_root / "body.stl", _stl_bytes(_shells_mesh(body)))
    put(gun_root / "tips.stl", _stl_bytes(_shells_mesh(tips)))
    put(gun_root / "tool.yaml", _tool_yaml(GUN).encode())
    return written


def write_tool(out: Path, name: str, body: Sequence[trimesh.Trimesh], tips: Sequence[trimesh.Trimesh],
               tool_yaml: str) -> list[Path]:
    """A tool's files under ``out`` (the ``robots/`` folder layout): body.stl, tips.stl, tool.yaml."""
    root = out / "tools" / name
    root.mkdir(parents=True, exist_ok=True)
    files = {"body.stl": _stl_bytes(_shells_mesh(body)), "tips.stl": _stl_bytes(_shells_mesh(tips)),
             "tool.yaml": tool_yaml.encode()}
    for file, data in files.items():
        (root / file).write_bytes(data)
    return [root / file for file in files]


def script_main(generate: Callable[[Path], list[Path]], doc: str | None, here: Path,
                argv: Sequence[str] | None = None) -> int:
    """A generator script's command line: ``--out DIR`` (default: the robots/ folder), the files printed."""
    parser = argparse.ArgumentParser(description=doc.split("\n", 1)[0] if doc else None)
    parser.add_argument("--out", type=Path, default=here,
                        help="output folder (default: the robots/ folder holding this script)")
    args = parser.parse_args(argv)
    for path in generate(args.out):
        print(path)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    return script_main(generate, __doc__, Path(__file__).resolve().parent, argv)


if __name__ == "__main__":
    raise SystemExit(main())
