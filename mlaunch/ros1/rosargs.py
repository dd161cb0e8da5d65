"""roslaunch's substitution args (``$(arg)``, ``$(find)``, ``$(eval)`` ...) on concrete values.

``mlaunch.ros1.config`` resolves a roslaunch file as roslaunch itself does (every argument
known); this is how it performs one attribute's text: each ``$(...)`` replaced, in the order
roslaunch replaces them, ``$(eval ...)`` only as the whole value.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from typing import Any

from mlaunch.plan.errors import LaunchFileError
from mlaunch.ros1.values import convert_value

VALID = ("arg", "dirname", "env", "eval", "find", "anon", "optenv")


class ArgMissing(LaunchFileError):
    """``$(arg x)`` of an argument that has no value (roslaunch's ArgException)."""

    def __init__(self, name: str) -> None:
        super().__init__(f"arg {name!r} is not set (declared without a value and not given)")
        self.name = name


class Substitutions:
    """What one context's ``$(...)`` read: its args, anonymous names, file, environment."""

    def __init__(
        self,
        args: dict[str, str],
        anon: dict[str, str],
        filename: str,
        environ: Mapping[str, str],
        find: Any,
    ) -> None:
        self.args = args
        self.anon = anon
        self.filename = filename
        self.environ = environ
        self.find = find  # package name -> its folder

    def resolve(self, text: str) -> str:
        """The attribute's text with every substitution performed (roslaunch's resolve_args)."""
        if not text:
            return text
        if text.startswith("$(eval ") and text.endswith(")"):
            return self.eval(text[7:-1])
        resolved = text
        for body in _collect(text):
            words = [w for w in body.split(" ") if w]
            if not words or words[0] not in VALID:
                raise LaunchFileError(
                    f"unknown substitution command $({body}); valid: {', '.join(VALID)}"
                )
            if words[0] == "eval":
                raise LaunchFileError(f"$(eval ...) must be the whole attribute value: {text!r}")
            value = self.command(words[0], words[1:], body)
            resolved = resolved.replace(f"$({body})", value)
        return resolved

    def command(self, command: str, args: list[str], body: str) -> str:
        if command == "dirname":
            return os.path.dirname(self.filename)
        if command == "optenv":
            if not args:
                raise LaunchFileError(f"$({body}) needs a variable name")
            return self.environ.get(args[0], " ".join(args[1:]))
        if len(args) != 1:
            raise LaunchFileError(f"$({body}) takes exactly one argument")
        (name,) = args
        if command == "arg":
            if name not in self.args:
                raise ArgMissing(name)
            return self.args[name]
        if command == "env":
            if name not in self.environ:
                raise LaunchFileError(f"environment variable {name!r} is not set: $({body})")
            return self.environ[name]
        if command == "find":
            return str(self.find(name))
        return self.anon_name(name)

    def anon_name(self, name: str) -> str:
        """rosgraph's anonymous name, the same for every use of ``name`` in this context."""
        if name not in self.anon:
            from mlaunch.plan.inputs import volatile

            volatile(f"$(anon {name}) is a new name in every run")
            unique = int.from_bytes(os.urandom(8), "big") >> 1
            raw = f"{name}_{os.uname().nodename}_{os.getpid()}_{unique}"
            self.anon[name] = re.sub(r"[.\-:]", "_", raw)
        return self.anon[name]

    def eval(self, expression: str) -> str:
        """``$(eval ...)``: Python over the args typed as roslaunch types them."""
        if "__" in expression:
            raise LaunchFileError("$(eval ...) may not contain double underscore expressions")

        def arg(name: str) -> Any:
            if name not in self.args:
                raise ArgMissing(name)
            return convert_value(self.args[name], "auto")

        functions: dict[str, Any] = {
            "arg": arg,
            "find": lambda p: str(self.find(p)),
            "env": lambda n: self.command("env", [n], f"env {n}"),
            "optenv": lambda n, d="": self.environ.get(n, d),
            "dirname": lambda: os.path.dirname(self.filename),
            "anon": self.anon_name,
            "true": True,
            "false": False,
        }
        names = {k: convert_value(v, "auto") for k, v in self.args.items()}
        names.update(functions)
        try:
            return str(eval(expression, {}, names))  # builtins too, as roslaunch
        except LaunchFileError:
            raise
        except Exception as e:
            raise LaunchFileError(f"$(eval {expression}) failed: {type(e).__name__}: {e}")


def _collect(text: str) -> list[str]:
    """The bodies of the ``$(...)`` in ``text``, left to right (no nesting, as roslaunch)."""
    found: list[str] = []
    i = 0
    while True:
        j = text.find("$(", i)
        if j < 0:
            return found
        k = text.find(")", j)
        if k < 0:
            raise LaunchFileError(f"'$(' is not closed in {text!r}")
        found.append(text[j + 2 : k])
        i = k + 1
