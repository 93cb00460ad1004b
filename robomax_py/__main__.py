"""`python -m robomax_py`: the `robomax` command."""

import signal
import sys


def _early(signum: int, frame: object) -> None:
    # SIGINT or SIGTERM while the command itself is being imported: nothing has started, so the
    # run ends quietly with 128 + signum; `cli.main` installs the handlers for the run.
    sys.exit(128 + signum)


signal.signal(signal.SIGTERM, _early)
if signal.getsignal(signal.SIGINT) is signal.default_int_handler:      # not when started ignoring it
    signal.signal(signal.SIGINT, _early)

# Imported after the handlers: importing the command takes a while.
from robomax_py.app.cli import main

main()
