"""A second, independent model of what each robot controller executes, used by tests to judge the
programs robomax writes.

Each dialect module (`krl`, `rapid`, `fanuc`, `urscript`) is a small, strict interpreter of a motion
subset written from the vendor's definitions (cited in its docstring), never from robomax_py's
export, program, verify or configuration code: it must not import them. It reads program text(s)
and returns a `common.ProgramRun`: every motion statement in execution order with its target as the
controller composes it (TCP in the controller's robot base frame, 4x4, metres), the tool and user
frames in force, the configuration data as written, and the program's process calls and waits.
Anything outside the subset that could change motion is an `Issue`, never silently skipped.
"""
