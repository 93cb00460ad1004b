"""A second, independent model of what each robot controller executes, used by tests to judge the
programs robomax writes.

Each dialect module is a small, strict interpreter of a motion subset written from the vendor's
definitions (cited in its docstring; the research behind them is /work/notes/vendor_research.md),
never from robomax_py's export, program, verify or configuration code, which it must not import:

- `common`   records (`ProgramRun`, `Motion`, `Call`, `Wait`, `Issue`, configuration data) and the
             vendors' rotation conventions
- `krl`      KUKA KSS 8.x .src/.dat: TCP = $BASE · target, BAS.SRC's frames from FDAT
- `rapid`    ABB RAPID modules: TCP = wobj uframe · oframe · target, tooldata tframe
- `fanuc`    FANUC TP .ls: TCP = UFRAME[UF] · position, UF/UT alarms, J2/J3 coupling
- `urscript` URScript: poses in the UR Base frame, set_tcp, pose_trans
- `kawasaki_as` Kawasaki AS: TCP = BASE · transformation (X, Y, Z, O, A, T; Rz·Ry·Rz), TOOL
- `inform`   Yaskawa INFORM jobs: pulse positions, rectangular positions in the base or USER n with
             TOOL n (the controller's frames, given by the caller)

Each reads program text(s) and returns a `common.ProgramRun`: every motion statement in execution
order with its target as the controller composes it (TCP in the controller's robot base frame,
4x4, metres), the tool and user frames in force, the configuration data as written, and the
program's process calls and waits. Anything outside the subset that could change motion is an
`Issue` with its line, never silently skipped.

Tests: ``test_<dialect>_model.py`` (hand-computed known values), ``test_public_programs.py``
(real programs from tests/data/programs), ``test_against_robomax.py`` (robomax's programs for a
cell placed away from the origin, judged in the world; slow).
"""
