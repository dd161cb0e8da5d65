"""roslaunch's ``$(eval)``: cut into parts when the file is read, evaluated as roslaunch does.

``EvalCutter`` checks an expression while reading and cuts it at every argument, ``find``,
``env`` ... it reads, so a converted file can write it as a ROS 2 PythonExpression.
``RoslaunchEval`` is the substitution that evaluates it at launch time with roslaunch's typing.
"""

from __future__ import annotations

import ast
import builtins
import os
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, Any

from mlaunch.launch.substitution import Substitution
from mlaunch.plan.errors import MlaunchError, SubstitutionFailure
from mlaunch.ros1.model import (
    AnonRef,
    ArgRef,
    DirnameRef,
    EnvRef,
    EvalArg,
    FindRef,
    Ref,
    called_name,
)
from mlaunch.ros1.values import convert_value

if TYPE_CHECKING:
    from typing import Protocol

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.plan.errors import LaunchFileError
    from mlaunch.ros1.scope import Scope

    class ArgChecks(Protocol):
        """What the cutter asks of the file's reader (mlaunch.ros1.elements' ElementReader is
        one) about an argument an expression reads; ``el`` is the reader's element, passed back
        as it came."""

        def arg_kind(self, name: str, scope: Scope) -> str: ...

        def check_arg(self, name: str, el: Any, scope: Scope) -> None: ...

        def error(self, el: Any, message: str) -> LaunchFileError: ...


EVAL_FUNCTIONS = ("arg", "find", "env", "optenv", "dirname", "anon")


class EvalCutter:
    """Cuts an ``$(eval)`` expression at the names and calls that read launch state."""

    def __init__(self, reader: ArgChecks, el: object, scope: Scope, expression: str) -> None:
        self.reader = reader
        self.el = el
        self.scope = scope
        self.expression = expression
        lines = expression.split("\n")
        self.starts = [0]
        for line in lines[:-1]:
            self.starts.append(self.starts[-1] + len(line) + 1)
        self.lines = lines
        self.cuts: list[tuple[int, int, str | EvalArg]] = []
        self.writable = True

    def offset(self, line: int, col: int) -> int:
        raw = self.lines[line - 1].encode("utf-8")[:col]
        return self.starts[line - 1] + len(raw.decode("utf-8", "replace"))

    def span(self, node: ast.expr) -> tuple[int, int]:
        end_line = node.end_lineno or node.lineno
        end_col = node.end_col_offset or node.col_offset
        return self.offset(node.lineno, node.col_offset), self.offset(end_line, end_col)

    def cut(self, tree: ast.Expression) -> tuple[str | EvalArg, ...] | None:
        self.visit(tree.body)
        if not self.writable:
            return None
        pieces: list[str | EvalArg] = []
        at = 0
        for start, end, piece in sorted(self.cuts, key=lambda c: c[0]):
            if start > at:
                pieces.append(self.expression[at:start])
            pieces.append(piece)
            at = end
        if at < len(self.expression):
            pieces.append(self.expression[at:])
        return tuple(pieces)

    def visit(self, node: ast.AST) -> None:
        function = called_name(node)
        if function in EVAL_FUNCTIONS and isinstance(node, ast.Call):
            self.call(node, function)
            return
        if isinstance(node, ast.Name):
            self.name(node)
            return
        for child in ast.iter_child_nodes(node):
            self.visit(child)

    def name(self, node: ast.Name) -> None:
        start, end = self.span(node)
        if node.id in self.scope.args:
            kind = self.reader.arg_kind(node.id, self.scope)
            self.cuts.append((start, end, EvalArg(ArgRef(node.id), kind)))
        elif node.id in ("true", "false"):
            self.cuts.append((start, end, node.id.capitalize()))
        elif node.id not in _EVAL_BUILTINS and node.id not in EVAL_FUNCTIONS:
            raise self.reader.error(
                self.el,
                f"$(eval {self.expression}): {node.id!r} is neither a declared arg nor a name"
                " roslaunch's eval knows",
            )

    def call(self, node: ast.Call, function: str) -> None:
        texts = [a.value for a in node.args if isinstance(a, ast.Constant)]
        if (
            len(texts) != len(node.args)
            or node.keywords
            or not all(isinstance(t, str) for t in texts)
        ):
            self.writable = False
            for child in node.args:
                self.visit(child)
            return
        args = [str(t) for t in texts]
        ref: Ref
        kind = "str"
        if function == "arg" and len(args) == 1:
            self.reader.check_arg(args[0], self.el, self.scope)
            ref, kind = ArgRef(args[0]), self.reader.arg_kind(args[0], self.scope)
        elif function == "find" and len(args) == 1:
            ref = FindRef(args[0])
        elif function == "env" and len(args) == 1:
            ref = EnvRef(args[0])
        elif function == "optenv" and len(args) in (1, 2):
            ref = EnvRef(args[0], args[1] if len(args) == 2 else "")
        elif function == "anon" and len(args) == 1:
            ref = AnonRef(args[0])
        elif function == "dirname" and not args:
            ref = DirnameRef()
        else:
            raise self.reader.error(
                self.el, f"$(eval {self.expression}): {function}() got {len(args)} argument(s)"
            )
        start, end = self.span(node)
        self.cuts.append((start, end, EvalArg(ref, kind)))


_EVAL_BUILTINS = frozenset(vars(builtins))


class _EvalNames(Mapping[str, Any]):
    """The names roslaunch's eval sees: functions, then args typed as roslaunch types them."""

    def __init__(self, functions: dict[str, Any], args: Mapping[str, Any]) -> None:
        self.functions = functions
        self.args = args

    def __getitem__(self, key: str) -> Any:
        if key in self.functions:
            return self.functions[key]
        value = self.args[key]
        return convert_value(value, "auto") if isinstance(value, str) else value

    def __iter__(self) -> Iterator[str]:
        return iter({**self.functions, **self.args})

    def __len__(self) -> int:
        return len({**self.functions, **self.args})


class RoslaunchEval(Substitution):
    """``$(eval expr)`` exactly as roslaunch evaluates it (args typed, find/env/... callable)."""

    def __init__(self, expression: str) -> None:
        self.expression = expression

    def perform(self, context: LaunchContext) -> str:
        configs = {k: v for k, v in context.launch_configurations.items() if isinstance(v, str)}

        def arg(name: str) -> Any:
            if name not in configs:
                raise SubstitutionFailure(f"$(eval): arg {name!r} is not set")
            return convert_value(configs[name], "auto")

        def find(package: str) -> str:
            from mlaunch.ros import packages

            return str(packages.for_context(context).get(package).share_directory)

        def env(name: str) -> str:
            if name not in context.environment:
                raise SubstitutionFailure(f"$(eval): environment variable {name!r} is not set")
            return context.environment[name]

        def optenv(name: str, default: str = "") -> str:
            return context.environment.get(name, default)

        def dirname() -> str:
            return os.path.dirname(context.current_launch_file_path or "")

        def anon(name: str) -> str:
            from mlaunch.launch.substitutions.anon_name import AnonName

            return AnonName(name).perform(context)

        functions: dict[str, Any] = {"arg": arg, "find": find, "env": env, "optenv": optenv}
        functions.update({"dirname": dirname, "anon": anon, "true": True, "false": False})
        try:
            return str(eval(self.expression, {}, _EvalNames(functions, configs)))
        except MlaunchError:
            raise
        except Exception as e:
            raise SubstitutionFailure(f"$(eval {self.expression}) failed: {type(e).__name__}: {e}")

    def describe(self) -> str:
        return f"$(eval {self.expression})"
