"""The compiled kernels every spot plan calls, with the argument types it calls them with: what
`compile_ahead` compiles before a first plan. The reference cell's plan (`tests/data/reference`)
compiles exactly these in a fresh cache (a test plans it and compares, naming the entries to write
here when they differ). Kernels that only some cells call (the C-space searches, the held part's
voxels, a station's clash tests, the numeric IK's iterations) compile at their first call, as before.

SHARED_HELPERS are the compiled helpers two of those kernels call (each kernel's compile would
compile them again in its own process): compiled once before the kernels are shared out.

cost_s: CPU seconds of the kernel's compile, the functions it calls included (numba's compile
events, this machine type); only their proportions matter: they share the kernels out among the
compiling processes.
"""

from __future__ import annotations

from dataclasses import dataclass

from numba.core import types as nt


@dataclass(frozen=True, slots=True)
class KernelEntry:
    module: str
    name: str
    args: tuple[nt.Type, ...]
    cost_s: float


def _array(dtype: nt.Type, ndim: int, readonly: bool = False) -> nt.Array:
    return nt.Array(dtype, ndim, "C", readonly=readonly)


_F1, _F2, _F3 = _array(nt.float64, 1), _array(nt.float64, 2), _array(nt.float64, 3)
_F2_READ = _array(nt.float64, 2, readonly=True)
_I1 = _array(nt.int64, 1)
_INT = nt.int64

PLAN_KERNELS = (
    KernelEntry("robomax_py.world.prefilter_kernels", "_uncleared",
                (_F2_READ, _F1, _F2, _F3, _I1, _array(nt.boolean, 2), _array(nt.boolean, 2), _I1,
                 _array(nt.int8, 1)), 2.8),
    KernelEntry("robomax_py.world.prefilter_kernels", "_near",
                (_F2_READ, _F1, _F2, _F3, _I1, _array(nt.boolean, 1), nt.boolean), 2.3),
    KernelEntry("robomax_py.timing._estimate_kernels", "straight_times",
                (_F2_READ, _F2_READ, _F1, _F1, nt.float64, nt.boolean), 0.3),
    KernelEntry("robomax_py.plan.min_plus", "min_plus_arg", (_F1, _F2, _F1), 0.25),
    KernelEntry("robomax_py.plan.min_plus", "min_plus", (_F1, _F2, _F1), 0.15),
    KernelEntry("robomax_py.plan.min_plus", "min_plus_product", (_F2, _F2), 0.2),
)

SHARED_HELPERS = (
    KernelEntry("robomax_py.world.prefilter_kernels", "_forward", (_F1, _F2, _F3, _I1, _F3, _F2), 0.35),
    KernelEntry("robomax_py.world.box_separation", "boxes_apart",
                (_F2, _F3, _F2, _INT, _F2, _F3, _F2, _INT, nt.float64, _F2), 0.5),
    KernelEntry("robomax_py.world.prefilter_kernels", "_place_box",
                (_F3, _F2, _INT, _F2, _F3, _I1, _INT, _F2, _F3), 0.1),
    KernelEntry("robomax_py.world.prefilter_kernels", "_place", (_F3, _F2, _INT, _F2, _INT, _F2, _INT), 0.05),
    KernelEntry("robomax_py.world.prefilter_kernels", "_sphere_box", (_F2, _INT, nt.float64, _F2, _INT, _INT), 0.05),
    KernelEntry("robomax_py.world.prefilter_kernels", "_sphere_point", (_F2, _INT, _F2, _INT, nt.float64), 0.03),
)
