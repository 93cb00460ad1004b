"""The `robomax` commands, one module per group, each registering its commands on `base.app` with
the conventions `base` sets (exit codes, --json, help); robomax_py.app.cli runs the app.

Imported here in the order the help lists the commands (hence not sorted), so that they are
registered in that order whichever module is imported first.
"""

from robomax_py.app.commands import (  # noqa: F401, I001
    checking,
    planning,
    replanning,
    measuring,
    viewing,
    batches,
    importing,
)
