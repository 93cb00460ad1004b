"""Whether the process that left a folder behind has ended: the one test behind the clean-ups of
killed runs' leftovers (`robomax import-urdf`'s staging folders, Ray tasks' copies of their cells).

Only POSIX can ask: `os.kill(pid, 0)` sends no signal there and fails for a process that no longer
exists. On Windows the same call does not ask anything (signal 0 is CTRL_C_EVENT, any other number
ends the process), so there no process counts as ended and nothing is removed.
"""

from __future__ import annotations

import os


def process_ended(pid: int) -> bool:
    """True only when process `pid` certainly no longer runs; False when it runs, when it is another
    user's (which says it exists), when `pid` is no process number, and wherever the system cannot
    tell (not POSIX)."""
    if os.name != "posix":
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except (PermissionError, OverflowError):
        return False
    return False
