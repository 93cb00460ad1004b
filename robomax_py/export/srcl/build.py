"""SRCL read: the parse tree built into a `Program`."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Literal

from lark import Token, Tree

from robomax_py.errors import ExportError, ProgramError
from robomax_py.export.srcl.grammar import _PLAIN_NUMBER
from robomax_py.export.srcl.write import _PROVENANCE, _STAMP, lin_frames
from robomax_py.program import (
    Comment,
    FrameDef,
    Gripper,
    Header,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Spot,
    Wait,
    WaitFor,
    find_problem,
)

# --------------------------------------------------------------------------------------------------
# tree -> Program


class _Builder:
    def __init__(self, file: str | Path | None) -> None:
        self.file = file
        self.lines: list[int] = []

    def error(self, line: int | None, column: int | None, problem: str) -> ProgramError:
        return ProgramError(self.file, f"line {line}, column {column}", problem)

    def number(self, token: Token) -> float:
        if not _PLAIN_NUMBER.fullmatch(str(token)):
            raise self.error(
                token.line, token.column,
                f"bad number '{token}': write digits with an optional '.' and decimals, e.g. 12.500",
            )
        return float(token)

    def whole(self, token: Token, low: int = 1) -> int:
        if not re.fullmatch(r"[0-9]+", str(token)) or int(str(token)) < low:
            raise self.error(token.line, token.column, f"expected a whole number from {low}, got '{token}'")
        return int(str(token))

    def tokens(self, tree: Tree[Token], kind: str) -> list[Token]:
        return [c for c in tree.children if isinstance(c, Token) and c.type == kind]

    def subtree(self, tree: Tree[Token], name: str) -> Tree[Token]:
        return next(c for c in tree.children if isinstance(c, Tree) and c.data == name)

    def triple(self, tree: Tree[Token]) -> tuple[float, ...]:
        return tuple(self.number(t) for t in self.tokens(tree, "NUMBER"))

    def check(self, tree: Tree[Token], item: Header | FrameDef | Instruction, n_joints: int) -> None:
        problem = find_problem(item, n_joints)
        if problem:
            raise self.error(tree.meta.line, tree.meta.column, problem)

    def program(self, tree: Tree[Token]) -> Program:
        name = self.tokens(tree, "IDENT")[0]
        header = self.header(self.subtree(tree, "header"))
        for comment in self.tokens(tree, "COMMENT"):
            text = str(comment)[1:-1].strip()
            match = _PROVENANCE.match(text)
            if match:
                sha = "" if match["sha"] == "unknown" else match["sha"]
                header = dataclasses.replace(header, generator=match["gen"], cell_sha256=sha)
            match = _STAMP.match(text)
            if match:
                header = dataclasses.replace(header, stamp=match["stamp"])
        n_joints = len(header.joints)
        frames = self.frames(self.subtree(tree, "frames"), n_joints)
        try:
            tool, base = lin_frames(tuple(frames))
        except ExportError as exc:
            raise self.error(tree.meta.line, tree.meta.column, str(exc)) from None
        instructions: list[Instruction] = []
        for child in tree.children:
            if isinstance(child, Tree) and child.data not in ("header", "frames"):
                ins = self.statement(child)
                if isinstance(ins, LinMove):
                    ins = dataclasses.replace(ins, tool=tool, base=base)
                self.check(child, ins, n_joints)
                instructions.append(ins)
                self.lines.append(child.meta.line)
        return Program(str(name), header, tuple(frames), tuple(instructions))

    def header(self, tree: Tree[Token]) -> Header:
        idents = self.tokens(tree, "IDENT")
        cell, robot, *joints, tool = idents
        seen: set[str] = set()
        for joint in joints:
            if str(joint) in seen:
                raise self.error(joint.line, joint.column, f"joint {str(joint)!r} is listed twice in AXES")
            seen.add(str(joint))
        (cycle,) = self.tokens(tree, "NUMBER")
        header = Header(str(cell), str(robot), str(tool), self.number(cycle), tuple(str(j) for j in joints))
        self.check(tree, header, len(joints))
        return header

    def frames(self, tree: Tree[Token], n_joints: int) -> list[FrameDef]:
        frames: list[FrameDef] = []
        for node in tree.children:
            if not (isinstance(node, Tree) and node.data == "frame"):
                continue
            (name,) = self.tokens(node, "IDENT")
            if any(f.name == str(name) for f in frames):
                raise self.error(name.line, name.column, f"frame {str(name)!r} is already defined")
            kind: Literal["tool", "base"] = \
                "tool" if any(isinstance(c, Tree) and c.data == "tool_kind" for c in node.children) else "base"
            number = [t for t in node.children if isinstance(t, Token) and t.type == "NUMBER"]
            frame = FrameDef(
                str(name), kind, self.triple(self.subtree(node, "pos")), self.triple(self.subtree(node, "ori")),
                self.whole(number[0], 0) if number else 0,
            )
            self.check(node, frame, n_joints)
            frames.append(frame)
        return frames

    def note(self, tree: Tree[Token]) -> str:
        comments = self.tokens(tree, "COMMENT")
        return str(comments[0])[1:-1].strip() if comments else ""

    def statement(self, tree: Tree[Token]) -> Instruction:
        fly = [c for c in tree.children if isinstance(c, Tree) and c.data == "flyby"]
        flyby = self.number(self.tokens(fly[0], "NUMBER")[0]) if fly else 0.0
        if tree.data == "ptp":
            values = [self.number(t) for t in self.tokens(tree, "NUMBER")]
            return PtpMove(tuple(values[:-2]), values[-2], values[-1], flyby, self.note(tree))
        if tree.data in ("lin", "spl", "slin"):
            (config,) = self.tokens(tree, "STRING")
            speed, *accel = self.tokens(tree, "NUMBER")
            return LinMove(
                self.triple(self.subtree(tree, "pos")), self.triple(self.subtree(tree, "ori")),
                str(config)[1:-1], self.number(speed), flyby, self.note(tree),
                accel=self.number(accel[0]) if accel else 1.0,
                spline="spl" if tree.data == "spl" else "slin" if tree.data == "slin" else "",
            )
        if tree.data == "spot":
            name, seam = self.tokens(tree, "IDENT")
            numbers = self.tokens(tree, "NUMBER")
            gun, schedule = (self.whole(t) for t in numbers[1:]) if len(numbers) == 3 else (1, 1)
            return Spot(str(name), str(seam), self.number(numbers[0]), gun, schedule)
        if tree.data == "gripper":
            name, seam = self.tokens(tree, "IDENT")
            (seconds,) = self.tokens(tree, "NUMBER")
            action: Literal["grip", "release"] = "grip" if self.tokens(tree, "GRIP") else "release"
            return Gripper(action, str(name), str(seam), self.number(seconds))
        if tree.data == "wait":
            (seconds,) = self.tokens(tree, "NUMBER")
            return Wait(self.number(seconds))
        if tree.data == "wait_for":
            (signal,) = self.tokens(tree, "IDENT")
            number = self.tokens(tree, "NUMBER")
            return WaitFor(str(signal), self.whole(number[0], 0) if number else None)
        if tree.data == "set_signal":
            (signal,) = self.tokens(tree, "IDENT")
            number = self.tokens(tree, "NUMBER")
            on = any(isinstance(c, Tree) and c.data == "set_on" for c in tree.children)
            return SetSignal(str(signal), self.whole(number[0], 0) if number else None, on)
        return Comment(self.note(tree))
