"""``mlaunch FILE --check``: what in a launch file Jazzy's ros2 launch rejects or reads otherwise.

mlaunch is lenient where Jazzy is strict (a YAML number where Jazzy wants text, mlaunch's own
``respawn: on-failure``, names mlaunch serves that Jazzy lacks), so a file that runs here can fail
on a robot. The check reads the file without running it:

- YAML and XML: every tag, attribute, sub-entity and ``$(...)`` against Jazzy's frontend table
  (mlaunch.check.jazzy), the YAML types Jazzy's ``get_attr`` refuses, the values it cannot read
  (``respawn``, ``on_exit``), and quotes that span a substitution in a command line (Jazzy
  splits the text between substitutions on its own, so ``cmd="sh -c 'echo $(var x)'"`` fails);
- Python: imports of ``launch``/``launch_ros`` names and keyword arguments Jazzy does not have
  (mlaunch.jazzy_python, recorded from the reference), ``mlaunch`` imports, and ``respawn=`` text
  Jazzy cannot read as a boolean;
- ROS 1 ``.launch`` files: ros2 launch cannot run them at all (``mlaunch convert`` can).

Files included with a path written out in full are checked too. Each finding is one line with
file:line:col, as errors are.
"""

from __future__ import annotations

import os
import re

from mlaunch.check import jazzy
from mlaunch.check.finding import Finding, reads_as_bool

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.frontends.element import Attr, Element

_YAML_STR = "tag:yaml.org,2002:str"
_YAML_TYPES = {
    "bool": ("tag:yaml.org,2002:bool",),
    "int": ("tag:yaml.org,2002:int",),
    "float": ("tag:yaml.org,2002:float",),  # Jazzy refuses a YAML int where it reads a float
}
_SUBSTITUTION = re.compile(r"\$\(\s*([A-Za-z0-9_-]+)")


def check(path: str) -> list[Finding]:
    """Every finding for the launch file at ``path`` and the files it includes by a plain path."""
    from mlaunch.frontends.limits import allow_deep_trees

    # The walks below are recursive like a run's (a substitution 200 deep is ~1,200 frames):
    # they get the same room, so the limits say where a file is too deep, not a RecursionError.
    allow_deep_trees()
    findings: list[Finding] = []
    seen: set[str] = set()
    todo = [os.path.abspath(path)]
    while todo:
        current = todo.pop(0)
        if current in seen:
            continue
        seen.add(current)
        found, includes = _check_one(current)
        findings += found
        todo += [i for i in includes if os.path.isfile(i)]
    return findings


def _check_one(path: str) -> tuple[list[Finding], list[str]]:
    from mlaunch import readers

    module = readers.frontend_for(path)
    if module == "mlaunch.ros1.roslaunch":
        return [
            Finding(
                path,
                "a ROS 1 launch file: ros2 launch cannot run it"
                " (mlaunch convert FILE --to py|yaml|xml writes a ROS 2 one)",
            )
        ], []
    if module == "mlaunch.frontends.python":
        # portability_python loads only for Python files.
        from mlaunch.check.portability_python import check_python

        return check_python(path)
    walker = _Walker(module.rsplit(".", 1)[1])
    root = readers.load_root(path)
    walker.root(root)
    return walker.findings, walker.includes


class _Walker:
    """Walks the Entities of a YAML or XML file against Jazzy's table, collecting findings."""

    def __init__(self, fmt: str) -> None:
        self.fmt = fmt
        self.findings: list[Finding] = []
        self.includes: list[str] = []

    def add(self, e: Element, message: str, attr: Attr | None = None) -> None:
        self.findings.append(Finding(e.where(attr), message))

    def root(self, root: Element) -> None:
        self.attributes(root, jazzy.ROOT)
        for child in root.children or []:
            self.action(child)

    def action(self, e: Element) -> None:
        table = jazzy.ACTIONS.get(e.tag)
        if e.tag in jazzy.NEWER_TAGS:
            self.add(e, jazzy.newer(f"the tag {e.tag!r}", jazzy.NEWER_TAGS[e.tag]))
            for attr in e.attrs.values():
                if isinstance(attr.value, str):
                    self.substitutions(e, attr, attr.value)
                elif isinstance(getattr(attr.value, "value", None), str):
                    self.substitutions(e, attr, attr.value.value)
            for child in e.children or []:
                self.action(child)
            return
        if table is None:
            if e.tag not in exposed()[0]:  # a package's tag is that package's to check
                self.add(e, f"Jazzy has no tag {e.tag!r}: ros2 launch rejects the file")
            return
        if e.tag in jazzy.BROKEN_ACTIONS:
            self.add(e, f"Jazzy's {e.tag} is broken: {jazzy.BROKEN_ACTIONS[e.tag]}")
        self.attributes(e, table)
        if e.tag == "include":
            self.include(e)
        children = e.children or []
        if e.tag in jazzy.TAKES_ACTIONS:
            for child in children:
                kind = table.get(child.tag, "")
                if self.fmt == "xml" and kind.startswith("entities:"):  # <group><keep/>
                    self.attributes(child, jazzy.SUBENTITIES[kind.split(":", 1)[1]])
                else:
                    self.action(child)
        elif self.fmt == "yaml" and children:
            self.add(e, f"Jazzy's {e.tag} takes no child entities")

    def attributes(self, e: Element, table: dict[str, str]) -> None:
        for name, attr in e.attrs.items():
            kind = table.get(name)
            if kind == "xml-only" and self.fmt == "yaml":
                kind = None
            if kind is None and name in jazzy.NEWER_SUBENTITIES:
                newer = jazzy.newer(repr(name), jazzy.NEWER_SUBENTITIES[name])
                self.add(e, newer, attr)
                continue
            if kind is None:
                self.add(
                    e, f"Jazzy's {e.tag} has no attribute {name!r}: ros2 launch rejects it", attr
                )
                continue
            if kind.startswith("entities:"):
                if self.fmt == "yaml":
                    for sub in e.yaml_subentities(e, name, attr):
                        self.attributes(sub, jazzy.SUBENTITIES[kind.split(":", 1)[1]])
                continue
            self.value(e, name, attr, kind)
        if self.fmt == "xml" and e.tag not in jazzy.TAKES_ACTIONS:
            for child in e.children or []:
                kind = table.get(child.tag, "")
                if child.tag in jazzy.NEWER_SUBENTITIES:
                    release = jazzy.NEWER_SUBENTITIES[child.tag]
                    self.add(child, jazzy.newer(f"<{child.tag}>", release))
                    continue
                if not kind.startswith("entities:"):
                    self.add(child, f"Jazzy's {e.tag} takes no <{child.tag}> inside it")
                    continue
                self.attributes(child, jazzy.SUBENTITIES[kind.split(":", 1)[1]])

    def value(self, e: Element, name: str, attr: Attr, kind: str) -> None:
        node = attr.value
        if not isinstance(node, str):  # a YAML node
            tag = getattr(node, "tag", "")
            if kind == "any":
                return
            if tag != _YAML_STR and tag not in _YAML_TYPES.get(kind, ()):
                self.add(e, _type_message(name, node, kind), attr)
                return
            text = node.value if isinstance(node.value, str) else ""
        else:
            text = node
        self.substitutions(e, attr, text)
        quoted = getattr(node, "tag", "") == _YAML_STR  # YAML text, not a YAML boolean
        if kind == "bool" and e.tag == "group" and quoted and reads_as_bool(text):
            self.add(
                e,
                f"Jazzy's group takes the text {text!r} as is, and any text is true there;"
                f" write {name}: {text.lower()} (a YAML boolean, unquoted)",
                attr,
            )
        if kind == "bool" and name == "allow_substs" and quoted:
            self.add(
                e,
                f"Jazzy's param takes allow_substs {text!r} in YAML as substitutions, which its"
                " ParameterFile refuses (a TypeError); write allow_substs: true or false (a YAML"
                " boolean, unquoted)",
                attr,
            )
        if kind == "respawn" and "$(" not in text and not reads_as_bool(text):
            self.add(
                e,
                f"Jazzy reads respawn as a boolean; {text!r} is mlaunch's own"
                " (write true or false)",
                attr,
            )
        elif kind == "on_exit" and text not in jazzy.ON_EXIT_WORDS:
            self.add(e, f"Jazzy's on_exit accepts only 'shutdown', not {text!r}", attr)
        elif kind == "cmdline" and "$(" in text:
            self.cmdline(e, attr, text)

    def substitutions(self, e: Element, attr: Attr, text: str) -> None:
        for match in _SUBSTITUTION.finditer(text):
            broken = jazzy.BROKEN_SUBSTITUTIONS.get(match.group(1))
            newer = jazzy.NEWER_SUBSTITUTIONS.get(match.group(1))
            if newer:
                self.add(e, jazzy.newer(f"$({match.group(1)} ...)", newer), attr)
            elif broken:
                self.add(e, f"Jazzy's $({match.group(1)} ...) is broken: {broken}", attr)
            elif match.group(1) not in jazzy.SUBSTITUTIONS and match.group(1) not in exposed()[1]:
                self.add(
                    e,
                    f"Jazzy has no substitution $({match.group(1)} ...): ros2 launch rejects it",
                    attr,
                )

    def cmdline(self, e: Element, attr: Attr, text: str) -> None:
        """Jazzy shlex-splits each text piece between substitutions on its own."""
        import shlex

        from mlaunch.launch.frontend.template import TemplateError
        from mlaunch.launch_ros.subst import parse_template

        try:
            parts = parse_template(text)
        except TemplateError:
            return  # mlaunch itself reports a malformed $(...) when it loads the file
        for part in parts if isinstance(parts, list) else [parts]:
            if not isinstance(part, str):
                continue
            try:
                shlex.split(part)
            except ValueError as err:
                self.add(
                    e,
                    f"Jazzy splits the command line between substitutions piece by piece, and"
                    f" {part.strip()!r} alone is {err} there; keep quotes from spanning $(...)",
                    attr,
                )
                return

    def include(self, e: Element) -> None:
        attr = e.attrs.get("file")
        text = None if attr is None else attr.value if isinstance(attr.value, str) else None
        if text is None and attr is not None:
            text = getattr(attr.value, "value", None)
        if not isinstance(text, str):
            return
        here = os.path.dirname(e.path)
        text = text.replace("$(dirname)", here)
        if "$(" not in text:
            self.includes.append(os.path.join(here, text))


def exposed() -> tuple[dict[str, Any], dict[str, Any]]:
    """The tags and the substitutions installed packages expose (``launch.frontend``), which
    ros2 launch accepts as it does its own; the extensions are loaded on the first question."""
    from mlaunch import compat
    from mlaunch.frontends.element import load_extensions
    from mlaunch.launch.frontend.expose import action_parse_methods, substitution_parse_methods

    compat.install()  # the extensions import the ROS 2 names
    load_extensions()
    return action_parse_methods, substitution_parse_methods


def _type_message(name: str, node: Any, kind: str) -> str:
    want = "text" if kind in ("text", "cmdline", "respawn", "on_exit") else kind
    shown = getattr(node, "value", "")
    if not isinstance(shown, str):
        return f"Jazzy reads {name!r} as {want}, not a YAML {_yaml_kind(node)}"
    fix = f"{name}: {shown}.0" if kind == "float" and shown.isdigit() else f"{name}: '{shown}'"
    return (
        f"Jazzy reads {name!r} as {want}: {shown!r} is YAML {_yaml_kind(node)} there,"
        f" a TypeError; write {fix}"
    )


def _yaml_kind(node: Any) -> str:
    tag = str(getattr(node, "tag", ""))
    return {
        "tag:yaml.org,2002:bool": "boolean",
        "tag:yaml.org,2002:int": "integer",
        "tag:yaml.org,2002:float": "float",
        "tag:yaml.org,2002:null": "null",
        "tag:yaml.org,2002:seq": "list",
        "tag:yaml.org,2002:map": "map",
    }.get(tag, tag.rsplit(":", 1)[-1])


def report(path: str, out: Any) -> int:
    """Print the findings for ``path``; 0 when there are none, 1 when there are."""
    findings = check(path)
    for finding in findings:
        print(finding, file=out)
    if findings:
        count = f"{len(findings)} finding{'s' if len(findings) != 1 else ''}"
        print(f"{count}: ros2 launch (Jazzy) would reject or read these differently", file=out)
        return 1
    print(f"{path}: nothing ros2 launch (Jazzy) would reject or read differently", file=out)
    return 0
