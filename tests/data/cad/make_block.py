#!/usr/bin/env python3
"""Write block.step, the CAD test part of tests/io/test_cad.py: a block 100 x 60 x 20 mm centred on
its origin with a through hole of radius 15 mm along z, in millimetres, made by OpenCASCADE through
build123d (`pip install build123d`; not needed to run the tests, which read the file written here).

    python tests/data/cad/make_block.py
"""

from pathlib import Path

import build123d as b3d

LENGTH, WIDTH, HEIGHT, HOLE_R = 100.0, 60.0, 20.0, 15.0   # mm: the test's exact solid


def main() -> None:
    part = b3d.Box(LENGTH, WIDTH, HEIGHT) - b3d.Cylinder(HOLE_R, HEIGHT)
    path = Path(__file__).with_name("block.step")
    assert b3d.export_step(part, str(path))


if __name__ == "__main__":
    main()
