"""The application: the `robomax` command, batch planning, benchmarks, reports, charts, preview
and URDF import. Nothing below imports from here."""
