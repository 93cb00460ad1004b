"""`python -m robomax_py`: the `robomax` command."""

import signal

# SIGINT and SIGTERM held from the first instant while the command is imported: an import that
# catches BaseException would swallow the exception a handler raises and the run would go on. A
# signal that came meanwhile is delivered once `main` has installed its handlers.
_before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})

from robomax_py.app.cli import main

main(restore_mask=_before)
