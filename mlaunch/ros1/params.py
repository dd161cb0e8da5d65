"""Reading roslaunch's ``<param>`` and ``<rosparam>``: values, types, and global parameters."""

from __future__ import annotations

import re
from typing import Any

import yaml

from mlaunch.frontends.encoding import not_utf8
from mlaunch.plan.yamldata import YamlLimitError
from mlaunch.plan.yamldata import load as load_yaml
from mlaunch.ros1.elements import Element, ElementReader
from mlaunch.ros1.model import (
    ArgRef,
    CommandRef,
    Cond,
    FileRef,
    Part,
    PValue,
    SetParam,
    Value,
    Warn,
    arg_names,
    describe_value,
    static_text,
    text,
)
from mlaunch.ros1.scope import Desc, Out, Pending, Scope, Skip
from mlaunch.ros1.values import PARAM_TYPES, VTYPES, RosparamLoader, convert_value, dotted

_MODEL_FILE = re.compile(r"([A-Za-z0-9_\-]+)\.(?:urdf\.xacro|xacro|urdf)\b")


class ParamReader(ElementReader):
    """The parameter tags of a roslaunch file (inside a node or global)."""

    def tag_param(self, el: Element, scope: Scope, out: Out) -> None:
        try:
            entries = self.param_entries(el, scope)
        finally:
            for message in self.drain_unheld():
                out.body.append(Warn(origin=self.origin(el), message=message))
        self.global_params(entries, el, scope, out)

    def param_entries(self, el: Element, scope: Scope) -> list[tuple[Value, PValue]]:
        """The (name, value) pairs one <param> sets (a yaml dict sets several)."""
        name = self.attr(el, "name", scope, required=True)
        assert name is not None
        given = [k for k in ("value", "textfile", "binfile", "command") if k in el.attrs]
        if len(given) != 1:
            raise self.error(
                el,
                "<param> needs exactly one of value, textfile, binfile, command"
                + (f" (got {', '.join(given)})" if given else ""),
            )
        type_name = (self.literal(el, "type", scope) or "auto").lower()
        if type_name not in PARAM_TYPES:
            raise self.error(
                el, f"type={type_name!r} is not a param type; valid: {', '.join(PARAM_TYPES)}"
            )
        source = given[0]
        raw = self.attr(el, source, scope, required=True)
        assert raw is not None
        if source == "binfile":
            raise Skip(
                "<param binfile> (binary data, an XML-RPC Base64 value) has no ROS 2 parameter"
                " type: the parameter is not set"
            )
        if source == "textfile":
            return [(name, PValue(dynamic=(FileRef(raw),), vtype=str))]
        if source == "command":
            vtype = None if type_name == "yaml" else VTYPES[type_name] or str
            return [(name, PValue(dynamic=(CommandRef(raw),), vtype=vtype))]
        found = static_text(raw)
        if found is None:
            auto = type_name == "auto"
            return [(name, PValue(dynamic=raw, vtype=VTYPES[type_name], auto=auto))]
        try:
            literal = convert_value(found.strip(), type_name)
        except (ValueError, yaml.YAMLError) as e:
            raise self.error(el, f"param value {found!r} is not of type {type_name}: {e}")
        return self.flatten(name, literal, el)

    def flatten(self, name: Value, value: Any, el: Element) -> list[tuple[Value, PValue]]:
        """A YAML value as ROS 2 parameters: dicts become dotted names, lists stay uniform."""
        if isinstance(value, dict):
            out: list[tuple[Value, PValue]] = []
            for key, inner in value.items():
                out += self.flatten((*name, "/", str(key)), inner, el)
            return out
        if numeric_rows(value):
            # nav2's footprint (and costmap polygons) take the ROS 1 list of points as text
            return [(name, PValue(literal=flow_text(value)))]
        problem = ros2_problem(value)
        if problem is not None:
            # only this key is lost: the load's other keys are set (each such key a warning)
            self.unheld.append(f"parameter {describe_value(name)}: {problem}; it is not set")
            return []
        if isinstance(value, (list, tuple)) and any(isinstance(v, float) for v in value):
            value = [float(v) for v in value]
        elif not isinstance(value, (bool, int, float, str, list)):
            value = str(value)  # dates and the like: roslaunch kept them as text-ish values
        return [(name, PValue(literal=list(value) if isinstance(value, tuple) else value))]

    def global_params(
        self, entries: list[tuple[Value, PValue]], el: Element, scope: Scope, out: Out
    ) -> None:
        cond = self.condition(el, scope)
        for name, value in entries:
            self.global_param(name, value, cond, el, scope, out)

    def global_param(
        self, name: Value, value: PValue, cond: Cond | None, el: Element, scope: Scope, out: Out
    ) -> None:
        """A parameter outside any node: where ROS 2 puts it depends on its name."""
        origin = self.origin(el)
        refs = frozenset(arg_names(name) | arg_names(value) | arg_names(cond))
        plain = static_text(name)
        target = "ns"
        if plain is not None:
            if plain.startswith("~"):
                message = (
                    f"private parameter {plain!r} outside a <node>: roslaunch gives it to each"
                    " later node of its scope (and so does a run); ROS 2 has no such rule, so a"
                    " converted file does not set it"
                )
                out.body.append(
                    Warn(origin=origin, condition=cond, scope_note=True, message=message)
                )
                return
            if plain.startswith("/"):
                inside = scope.ns is not None and scope.ns != "/"
                if inside and plain.startswith(scope.ns.rstrip("/") + "/"):  # type: ignore[union-attr]
                    plain = plain[len(scope.ns) + 1 :]  # type: ignore[arg-type]
                else:
                    target, plain = "root", plain.lstrip("/")
            ros2_name = dotted(plain)
            if ros2_name in ("robot_description", "use_gui"):
                desc = Desc(ros2_name, value, origin, cond, model=self.model_name(value, scope))
                self.descriptions.append(desc)
                out.pending.append(Pending(desc, target, refs))
                return
            name = text(ros2_name)
        else:
            name = tuple(dotted(p) if isinstance(p, str) else p for p in name)
        item = SetParam(origin=origin, condition=cond, name=name, value=value)
        out.pending.append(Pending(item, target, refs))

    def model_name(self, value: PValue, scope: Scope) -> str | None:
        """The robot model's file stem in a robot_description (following one $(arg))."""
        parts: list[Part] = list(value.dynamic or ())
        while parts:
            part = parts.pop(0)
            if isinstance(part, CommandRef):
                parts = [*part.command, *parts]
            elif isinstance(part, ArgRef):
                info = scope.args.get(part.name)
                if info is not None and info.default is not None:
                    parts = [*info.default, *parts]
            elif isinstance(part, str):
                found = _MODEL_FILE.findall(part)
                if found:
                    return str(found[-1])
        return None

    def tag_rosparam(self, el: Element, scope: Scope, out: Out) -> None:
        try:
            entries = self.rosparam_entries(el, scope)
        except Skip as skip:
            out.body.append(Warn(origin=self.origin(el), message=skip.message))
            return
        finally:
            for message in self.drain_unheld():
                out.body.append(Warn(origin=self.origin(el), message=message))
        if entries:
            self.global_params(entries, el, scope, out)

    def drain_unheld(self) -> list[str]:
        """The warnings for values ROS 2 cannot hold met since the last call."""
        found, self.unheld = self.unheld, []
        return found

    def rosparam_entries(self, el: Element, scope: Scope) -> list[tuple[Value, PValue]]:
        command = self.literal(el, "command", scope) or "load"
        if command in ("dump", "delete"):
            raise Skip(
                f"<rosparam command={command!r}> is skipped: ROS 2 has no parameter server to"
                f" {command} from"
            )
        if command != "load":
            raise self.error(el, f"command={command!r} is not valid; valid: load, dump, delete")
        subst = self.flag(el, "subst_value", scope)
        if not isinstance(subst, (bool, type(None))):
            raise self.error(el, "subst_value must be known when the file is read")
        data = self.rosparam_text(el, scope)
        try:
            loaded = load_yaml(data, el.attrs.get("file", ""), loader=RosparamLoader)
        except YamlLimitError as e:
            raise self.error(el, f"rosparam {e}")
        except (yaml.YAMLError, ValueError) as e:
            raise self.error(el, f"rosparam YAML is invalid: {e}")
        param = self.attr(el, "param", scope)
        if param is not None:
            loaded = {static_text(param) or "": loaded} if static_text(param) else loaded
            if static_text(param) is None:
                raise self.error(el, "param must be known when the file is read")
        if loaded is None:
            return []
        if not isinstance(loaded, dict):
            raise self.error(el, "'param' attribute must be set for non-dictionary values")
        ns = self.literal(el, "ns", scope)
        prefix: Value = text(ns) if ns else ()
        entries: list[tuple[Value, PValue]] = []
        for key, value in loaded.items():
            name: Value = (*prefix, "/", str(key)) if prefix else text(str(key))
            for entry in self.flatten(name, value, el):
                entries.append(self.substituted(entry, el, scope) if subst else entry)
        return entries

    def rosparam_text(self, el: Element, scope: Scope) -> str:
        path_value = self.attr(el, "file", scope)
        if path_value is None:
            return "".join(el.text)
        path = self.resolve_static(path_value, el)
        if path is None:
            raise Skip(
                f"rosparam file {el.attrs['file']!r} depends on launch arguments: mlaunch reads"
                " ROS 1 parameter files when it loads the launch file (ROS 2 nodes cannot read"
                " them), so give a fixed path ($(find pkg)/...); not loaded"
            )
        try:
            with open(path, "rb") as f:
                data = f.read()
        except OSError as e:
            raise self.error(el, f"cannot read rosparam file {path!r}: {e.strerror}")
        problem = not_utf8(data, path)
        if problem is not None:
            raise self.error(el, f"rosparam file {problem.where}: {problem.message}")
        return data.decode("utf-8")

    def substituted(
        self, entry: tuple[Value, PValue], el: Element, scope: Scope
    ) -> tuple[Value, PValue]:
        """subst_value: text values with $(...) are performed, then typed by YAML."""
        name, value = entry
        if isinstance(value.literal, str) and "$(" in value.literal:
            return name, PValue(dynamic=self.value(value.literal, el, "rosparam", scope))
        return entry


def ros2_value(value: Any) -> tuple[Any, str | None]:
    """A ROS 1 parameter value as a ROS 2 parameter holds it, or why it cannot be one."""
    if numeric_rows(value):
        return flow_text(value), None
    problem = ros2_problem(value)
    if problem is None and isinstance(value, bytes):
        problem = "binary data (binfile) has no ROS 2 parameter type"
    if problem is not None:
        return None, problem
    if isinstance(value, tuple):
        value = list(value)
    if isinstance(value, list) and any(isinstance(v, float) for v in value):
        return [float(v) for v in value], None
    if not isinstance(value, (bool, int, float, str, list)):
        return str(value), None  # dates and the like
    return value, None


def numeric_rows(value: Any) -> bool:
    """A list of lists of numbers (a footprint, a polygon): ROS 2 packages take it as text."""
    if not isinstance(value, (list, tuple)) or not value:
        return False
    return all(
        isinstance(row, (list, tuple))
        and row
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in row)
        for row in value
    )


def flow_text(value: Any) -> str:
    """``[[x, y], ...]`` as YAML's flow style writes it (nav2's footprint string)."""
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(flow_text(v) for v in value) + "]"
    return repr(value)


def ros2_problem(value: Any) -> str | None:
    """Why a YAML value cannot be a ROS 2 parameter, or None."""
    if value is None:
        return "an empty (null) value has no ROS 2 parameter type"
    if isinstance(value, (list, tuple)):
        if not value:
            return "an empty list has no ROS 2 parameter type"
        kinds = {bool if isinstance(v, bool) else type(v) for v in value}
        if kinds <= {int, float} or (len(kinds) == 1 and kinds <= {bool, str}):
            return None
        if any(isinstance(v, (dict, list, tuple)) for v in value):
            return "a list of maps or lists is not a ROS 2 parameter type"
        return "a list mixing types is not a ROS 2 parameter type"
    return None
