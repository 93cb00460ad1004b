"""Yaskawa INFORM jobs written with a convention the controller does not share are rejected by
`verify`, naming a line: the placed process cell's job edited as a mistaken writer would write it
(the robot's placement as the user frame, Rx and Rz swapped, pulses as degrees, the user frame
left out, the RCONF front/rear bit flipped, a weld time in ms)."""

from __future__ import annotations

import re

import pytest
from verify_mutants import Edit, Placed


def _user_frame_left_out(placed: Placed) -> dict[str, Edit]:
    return {".jbi": lambda t: t.replace("///POSTYPE USER", "///POSTYPE BASE")}


def _rx_rz_swapped(placed: Placed) -> dict[str, Edit]:
    def swap(m: re.Match[str]) -> str:
        v = m[2].split(",")
        return m[1] + ",".join([*v[:3], v[5], v[4], v[3]])
    return {".jbi": lambda t: re.sub(r"^(C\d{5}=)((?:-?[\d.]+,){5}-?[\d.]+)(?=\r?$)",
                                     lambda m: swap(m) if "." in m[2] else m[0], t, flags=re.MULTILINE)}


def _pulses_as_degrees(placed: Placed) -> dict[str, Edit]:
    ppd = placed.robot.controller.pulses_per_degree
    return {".jbi": lambda t: re.sub(r"^(C\d{5}=)((?:-?\d+,){5}-?\d+)(?=\r?$)",
                                     lambda m: m[1] + ",".join(str(round(int(p) / k)) for p, k in zip(m[2].split(","), ppd)),
                                     t, flags=re.MULTILINE)}


def _front_rear_flipped(placed: Placed) -> dict[str, Edit]:
    return {".jbi": lambda t: re.sub(r"(///RCONF \d,\d,)(\d)", lambda m: m[1] + str(1 - int(m[2])), t)}


def _weld_time_in_ms(placed: Placed) -> dict[str, Edit]:
    return {".jbi": lambda t: re.sub(r"(ARGF1 ARGF)([\d.]+)", lambda m: f"{m[1]}{1000 * float(m[2]):.3f}", t)}


def _end_before_the_first_weld(placed: Placed) -> dict[str, Edit]:
    return {".jbi": lambda t: t.replace("CALL JOB:SPOTWELD ARGF1", "END\r\nCALL JOB:SPOTWELD ARGF1", 1)}


MUTANTS = {
    "user frame left out": _user_frame_left_out,
    "Rx and Rz swapped": _rx_rz_swapped,
    "pulses as degrees": _pulses_as_degrees,
    "front / rear flipped": _front_rear_flipped,
    "weld time in ms": _weld_time_in_ms,
    "END before the first weld": _end_before_the_first_weld,
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(MUTANTS))
def test_inform_mutant_is_rejected(placed: Placed, kind: str) -> None:
    report = placed.verify("inform", MUTANTS[kind](placed), re.sub(r"\W+", "_", kind))
    assert not report.clean, kind


@pytest.mark.slow
def test_the_written_job_is_clean(placed: Placed) -> None:
    report = placed.verify("inform", {}, "unchanged")
    assert report.clean, report.violations
