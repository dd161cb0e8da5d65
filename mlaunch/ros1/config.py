"""A roslaunch file resolved exactly as roslaunch resolves it: its parameter server and nodes.

``load(path, args)`` walks the file as roslaunch's XML loader does, every launch argument known:
included files (whatever their suffix) with roslaunch's argument scoping, ``<group>`` and node
namespaces, remaps and env inherited by scope, ``<param>`` typed by roslaunch's rules, and
``<rosparam>`` loads flattened into one parameter server with absolute ROS 1 names. The result
(``Config``) is what ``roslaunch.config.load_config_default`` yields: what a native ROS 1 run
uploads and starts, and what the ROS 2 mapping distributes to nodes by ROS 1's name rules.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import yaml

from mlaunch.frontends.limits import IncludeChain
from mlaunch.plan.errors import LaunchFileError, MlaunchError
from mlaunch.plan.yamldata import load as load_yaml
from mlaunch.ros1.elements import Element, parse_xml
from mlaunch.ros1.rosargs import ArgMissing, Substitutions
from mlaunch.ros1.values import RosparamLoader, convert_value


@dataclass
class Ros1Node:
    """A ``<node>`` as roslaunch keeps it (``args`` substituted, split when it starts)."""

    package: str
    type: str
    name: str
    namespace: str  # global, ending in '/'
    args: str = ""
    remaps: list[tuple[str, str]] = field(default_factory=list)
    env: list[tuple[str, str]] = field(default_factory=list)
    output: str | None = None
    cwd: str | None = None
    launch_prefix: str | None = None
    required: bool = False
    respawn: bool = False
    respawn_delay: float = 0.0
    machine: str | None = None
    origin: str = ""

    @property
    def full_name(self) -> str:
        return ns_join(self.namespace, self.name)


@dataclass
class Config:
    """What a roslaunch file sets up: the parameter server, nodes, parameters to clear first."""

    params: dict[str, Any] = field(default_factory=dict)
    origins: dict[str, str] = field(default_factory=dict)
    nodes: list[Ros1Node] = field(default_factory=list)
    core_nodes: list[Ros1Node] = field(default_factory=list)  # roscore.xml's (rosout)
    clear_params: list[str] = field(default_factory=list)
    machines: dict[str, dict[str, Any]] = field(default_factory=dict)
    files: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def set(self, key: str, value: Any, origin: str, unroll: bool = True) -> None:
        """Set one parameter; a map is unrolled into its leaves as a <rosparam> load does
        (a ``<param type="yaml">`` map stays one value: ``unroll`` false)."""
        if isinstance(value, dict) and unroll:
            for k, v in value.items():
                self.set(ns_join(key, str(k)), v, origin)
            return
        key = canonical(key)
        self.params[key] = value
        self.origins[key] = origin


# --- ROS 1 names --------------------------------------------------------------------------------


def canonical(name: str) -> str:
    """rosgraph's canonicalize_name: no repeated or trailing separators."""
    if not name or name == "/":
        return name
    inner = "/".join(p for p in name.split("/") if p)
    return "/" + inner if name.startswith("/") else inner


def ns_join(ns: str, name: str) -> str:
    """rosgraph's ns_join: global and private names stay, others go under ``ns``."""
    if name.startswith(("/", "~")):
        return name
    if ns == "~":
        return "~" + name
    if not ns:
        return name
    return ns + name if ns.endswith("/") else ns + "/" + name


def global_ns(ns: str) -> str:
    """rosgraph's make_global_ns: absolute, ending in '/'."""
    if not ns.startswith("/"):
        ns = "/" + ns
    return ns if ns.endswith("/") else ns + "/"


# --- the walk -----------------------------------------------------------------------------------


class Context:
    """roslaunch's LoaderContext: namespace, args, private params, remaps and env of a scope."""

    def __init__(
        self,
        ns: str,
        subst: Substitutions,
        parent: Context | None = None,
        params: list[tuple[str, Any, str]] | None = None,
        env: list[tuple[str, str]] | None = None,
        arg_names: list[str] | None = None,
    ) -> None:
        self.ns = global_ns(ns or "/")
        self.subst = subst
        self.parent = parent
        self.params = params if params is not None else []
        self.env = env or []
        self.remaps: list[tuple[str, str]] = []
        self.arg_names = arg_names or []
        self.include_args: dict[str, str] | None = None  # an <include>'s args being collected
        self.pass_all_args = False

    def child(self, ns: str | None) -> Context:
        child_ns = self.ns if not ns else ns if ns.startswith("/") else ns_join(self.ns, ns)
        s = self.subst
        subst = Substitutions(dict(s.args), dict(s.anon), s.filename, s.environ, s.find)
        ctx = Context(child_ns, subst, self, self.params, list(self.env), list(self.arg_names))
        ctx.include_args = self.include_args
        return ctx

    def add_arg(self, name: str, value: str | None, default: str | None) -> None:
        if name in self.arg_names:
            if not self.pass_all_args:
                raise LaunchFileError(f"arg {name!r} has already been declared")
        else:
            self.arg_names.append(name)
        args = self.subst.args if self.include_args is None else self.include_args
        if value is not None:
            if name in args and not self.pass_all_args:
                raise LaunchFileError(f"cannot override arg {name!r}, which has already been set")
            args[name] = value
        elif default is not None and name not in args:
            args[name] = default

    def add_remap(self, src: str, dst: str) -> None:
        src, dst = canonical(src), canonical(dst)
        if not src or not dst:
            raise LaunchFileError("remap from/to attributes cannot be empty")
        self.remaps = [r for r in self.remaps if r[0] != src]
        self.remaps.append((src, dst))

    def remap_args(self) -> list[tuple[str, str]]:
        if self.parent is None:
            return list(self.remaps)
        own = {r[0] for r in self.remaps}
        return [r for r in self.parent.remap_args() if r[0] not in own] + self.remaps


def bool_attr(value: str | None, default: bool, what: str) -> bool:
    """roslaunch's _bool_attr: only true/false (any case)."""
    if value is None:
        return default
    lowered = value.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    raise LaunchFileError(f"invalid bool value for {what}: {value!r} (valid: true, false)")


class Loader:
    """Walks a roslaunch file (and its includes) into a ``Config``."""

    def __init__(self, environ: Mapping[str, str], find: Any, run_command: Any) -> None:
        self.environ = environ
        self.find = find
        self.run_command = run_command
        self.config = Config()
        self.default_machine: str | None = None
        self.origin = ""
        self.includes = IncludeChain()

    def load(self, path: str, args: Mapping[str, str], core: bool = False) -> Config:
        """The file's configuration; with ``core``, roslaunch's roscore.xml first (as
        roslaunch loads it: /rosversion, /rosdistro and rosout), where ROS 1 is installed."""
        if core:
            self.core()
        path = os.path.abspath(path)
        subst = Substitutions(dict(args), {}, path, self.environ, self.find)
        root = Context(self.environ.get("ROS_NAMESPACE", "/"), subst)
        self.file(path, root)
        return self.config

    def core(self) -> None:
        try:
            roslaunch = self.find("roslaunch")
        except LaunchFileError:
            return
        path = os.path.join(roslaunch, "resources", "roscore.xml")
        if not os.path.isfile(path):
            return
        nodes, self.config.nodes = self.config.nodes, []
        self.file(path, Context("/", Substitutions({}, {}, path, self.environ, self.find)))
        self.config.core_nodes, self.config.nodes = self.config.nodes, nodes

    def file(self, path: str, ctx: Context) -> None:
        root = parse_xml(path)
        if root.tag != "launch":
            raise LaunchFileError(
                f"the root element must be <launch>, not <{root.tag}>", where=path
            )
        real = os.path.realpath(path)  # (an include may name it through a symlink)
        if real not in self.config.files:
            self.config.files.append(real)
        self.walk(root.children, ctx, path)

    def walk(self, elements: list[Element], ctx: Context, path: str) -> None:
        for el in elements:
            self.origin = f"{path}:{el.line}"
            try:
                self.element(el, ctx, path)
            except MlaunchError as e:
                if not e.where:
                    e.where = self.origin
                    e.what = e.what or f"<{el.tag}>"
                raise

    def attr(self, el: Element, name: str, ctx: Context) -> str | None:
        raw = el.attrs.get(name)
        return None if raw is None else ctx.subst.resolve(raw)

    def required(self, el: Element, name: str, ctx: Context) -> str:
        value = self.attr(el, name, ctx)
        if value is None:
            raise LaunchFileError(f"missing required attribute {name!r}")
        return value

    def applies(self, el: Element, ctx: Context) -> bool:
        """roslaunch's if/unless test."""
        when, unless = self.attr(el, "if", ctx), self.attr(el, "unless", ctx)
        if when is not None and unless is not None:
            raise LaunchFileError("cannot set both 'if' and 'unless' on the same tag")
        if when is not None:
            return bool(convert_value(when, "bool"))
        if unless is not None:
            return not convert_value(unless, "bool")
        return True

    def element(self, el: Element, ctx: Context, path: str) -> None:
        tag = el.tag
        if tag not in ("arg", "group", "include", "node", "test") and not self.applies(el, ctx):
            return
        if tag == "arg":
            if self.applies(el, ctx):
                self.tag_arg(el, ctx)
        elif tag == "group":
            if self.applies(el, ctx):
                inner = self.scoped(el, ctx, "group")
                inner.params = list(inner.params)
                self.walk(el.children, inner, path)
        elif tag == "include":
            if self.applies(el, ctx):
                self.tag_include(el, ctx, path)
        elif tag == "node":
            if self.applies(el, ctx):
                self.config.nodes.append(self.tag_node(el, ctx))
        elif tag == "param":
            self.tag_param(el, ctx, None)
        elif tag == "rosparam":
            self.tag_rosparam(el, ctx)
        elif tag == "remap":
            ctx.add_remap(self.required(el, "from", ctx), self.required(el, "to", ctx))
        elif tag == "env":
            ctx.env.append((self.required(el, "name", ctx), self.required(el, "value", ctx)))
        elif tag == "machine":
            self.tag_machine(el, ctx)
        elif tag != "master" and tag != "test":
            self.config.warnings.append(f"{self.origin}: unrecognized tag <{tag}>")

    def scoped(self, el: Element, ctx: Context, tag: str, node_name: str = "") -> Context:
        """A child context for a tag with ``ns`` / ``clear_params`` (roslaunch's rules)."""
        ns = self.attr(el, "ns", ctx)
        if ns is not None and not ns:
            raise LaunchFileError(f"<{tag}> tag has an empty 'ns' attribute")
        inner = ctx.child(ns)
        if bool_attr(self.attr(el, "clear_params", ctx) or None, False, "clear_params"):
            if tag == "node":
                self.config.clear_params.append(global_ns(ns_join(inner.ns, node_name)))
            elif not ns:
                raise LaunchFileError("'ns' attribute must be set in order to use 'clear_params'")
            else:
                self.config.clear_params.append(inner.ns)
        return inner

    def tag_arg(self, el: Element, ctx: Context) -> None:
        name = self.required(el, "name", ctx)
        value, default = self.attr(el, "value", ctx), self.attr(el, "default", ctx)
        if value is not None and default is not None:
            raise LaunchFileError("<arg> tag must have one and only one of value/default")
        ctx.add_arg(name, value, default)

    def tag_include(self, el: Element, ctx: Context, path: str) -> None:
        where = f"{path}:{el.line}"
        filename = self.required(el, "file", ctx)
        pass_all = bool_attr(self.attr(el, "pass_all_args", ctx), False, "pass_all_args")
        inner = self.scoped(el, ctx, "include")
        inner.arg_names = []
        inner.include_args = {}
        if pass_all:
            for name, value in ctx.subst.args.items():
                inner.add_arg(name, value, None)
            inner.pass_all_args = True
        for child in el.children:
            self.origin = f"{path}:{child.line}"
            if child.tag == "env" and self.applies(child, inner):
                inner.env.append(
                    (self.required(child, "name", inner), self.required(child, "value", inner))
                )
            elif child.tag == "arg" and self.applies(child, inner):
                self.tag_arg(child, inner)
        passed = inner.include_args
        missing = [n for n in inner.arg_names if n not in passed]
        if missing:
            raise LaunchFileError(f"include args must have declared values: {', '.join(missing)}")
        included = os.path.abspath(filename)
        s = inner.subst
        inner.subst = Substitutions(dict(passed), {}, included, s.environ, s.find)
        inner.arg_names, inner.include_args = [], None
        # The same file with the same args, namespace and env where it is already being read
        # would repeat forever: an error naming the chain, as the other readers give.
        state: dict[str, object] = {**passed, " ns": inner.ns}
        try:
            with self.includes.enter_state(included, where, state, dict(inner.env)):
                self.file(included, inner)
        except ArgMissing as e:
            raise LaunchFileError(f"included file {included} requires the {e.name!r} arg to be set")

    def tag_node(self, el: Element, ctx: Context) -> Ros1Node:
        name = self.required(el, "name", ctx)
        inner = self.scoped(el, ctx, "node", name)
        private = Context(ns_join(inner.ns, name), inner.subst, None, [], [], [])
        node = Ros1Node(
            package=self.required(el, "pkg", ctx),
            type=self.required(el, "type", ctx),
            name=name,
            namespace=inner.ns,
            args=self.attr(el, "args", ctx) or "",
            output=self.attr(el, "output", ctx),
            cwd=self.attr(el, "cwd", ctx),
            launch_prefix=self.attr(el, "launch-prefix", ctx) or None,
            required=bool_attr(self.attr(el, "required", ctx), False, "required"),
            respawn=bool_attr(self.attr(el, "respawn", ctx), False, "respawn"),
            machine=self.attr(el, "machine", ctx) or self.default_machine,
            origin=self.origin,
        )
        delay = self.attr(el, "respawn_delay", ctx)
        node.respawn_delay = float(delay) if delay else 0.0
        if node.output not in (None, "log", "screen"):
            raise LaunchFileError(f"output={node.output!r} is not valid; valid: log, screen")
        remaps, env = ctx.child(""), ctx.child("")
        for child in el.children:
            if not self.applies(child, ctx):
                continue
            if child.tag == "remap":
                remaps.add_remap(self.required(child, "from", ctx), self.required(child, "to", ctx))
            elif child.tag == "param":
                self.tag_param(child, ctx, private)
            elif child.tag == "rosparam":
                self.tag_rosparam(child, private)
            elif child.tag == "env":
                env.env.append(
                    (self.required(child, "name", ctx), self.required(child, "value", ctx))
                )
        for key, value, origin in [*ctx.params, *private.params]:
            key = private.ns + (key[1:] if key[0] == "~" else key)
            self.config.set(key, value, origin, unroll=False)
        node.remaps = remaps.remap_args()
        node.env = env.env
        return node

    def tag_param(self, el: Element, ctx: Context, private: Context | None) -> None:
        kind = (el.attrs.get("type") or "auto").lower().strip()
        sources = ("value", "textfile", "binfile", "command")
        given = {k: self.attr(el, k, ctx) for k in sources if k in el.attrs}
        if len(given) != 1:
            raise LaunchFileError(
                "<param> tag must have one and only one of value/textfile/binfile"
            )
        name = ctx.subst.resolve(el.attrs.get("name", "").strip())
        if not name:
            raise LaunchFileError("<param> tag is missing required attribute 'name'")
        value = self.param_value(kind, *next(iter(given.items())))
        if private is not None:
            private.params = [p for p in private.params if p[0] != name]
            private.params.append((name, value, self.origin))
        elif name.startswith("~"):
            ctx.params[:] = [p for p in ctx.params if p[0] != name] + [(name, value, self.origin)]
        else:
            self.config.set(ns_join(ctx.ns, name), value, self.origin, unroll=False)

    def param_value(self, kind: str, source: str, text: Any) -> Any:
        try:
            if source == "value":
                return convert_value(text.strip(), kind)
            if source == "binfile":
                with open(text, "rb") as f:
                    return f.read()
            if source == "textfile":
                with open(text, encoding="utf-8") as f:
                    return convert_value(f.read(), kind)
            from mlaunch.ros1 import lookup

            note = lookup.renamed_command(text)
            if note:
                self.config.warnings.append(f"{self.origin}: {note}")
            return convert_value(self.run_command(text), kind)
        except OSError as e:
            raise LaunchFileError(f"cannot read {source} {text!r}: {e.strerror}")
        except (ValueError, yaml.YAMLError) as e:
            raise LaunchFileError(f"invalid <param> value: {e}")

    def tag_rosparam(self, el: Element, ctx: Context) -> None:
        attrs = {k: self.attr(el, k, ctx) for k in ("command", "ns", "file", "param")}
        subst = bool_attr(self.attr(el, "subst_value", ctx), False, "subst_value")
        param = ns_join(attrs["ns"] or "", attrs["param"] or "")
        command = attrs["command"] or "load"
        if command not in ("load", "dump", "delete"):
            raise LaunchFileError("command must be 'load', 'dump', or 'delete'")
        full = ns_join(ctx.ns, param) if param else ctx.ns
        if command != "load":
            return  # run-time rosparam programs, not configuration
        text = "".join(el.text)
        if attrs["file"]:
            try:
                with open(attrs["file"], encoding="utf-8") as f:
                    text = f.read()
            except OSError as e:
                raise LaunchFileError(f"file does not exist [{attrs['file']}]: {e.strerror}")
        if subst:
            text = ctx.subst.resolve(text)
        try:
            data = load_yaml(text, attrs["file"] or "<rosparam>", loader=RosparamLoader)
        except yaml.YAMLError as e:
            raise LaunchFileError(f"invalid YAML in <rosparam>: {e}")
        if data is None:
            data = {}
        if not param and not isinstance(data, dict):
            raise LaunchFileError("'param' attribute must be set for non-dictionary values")
        self.config.set(full, data, self.origin)

    def tag_machine(self, el: Element, ctx: Context) -> None:
        name = self.required(el, "name", ctx)
        fields = ("address", "env-loader", "ssh-port", "user", "password", "default", "timeout")
        found = {k: self.attr(el, k, ctx) for k in fields}
        if not found["address"]:
            raise LaunchFileError("<machine> tag is missing required attribute 'address'")
        self.config.machines[name] = found
        if (found["default"] or "false").lower() == "true":
            self.default_machine = name


def load(
    path: str,
    args: Mapping[str, str],
    environ: Mapping[str, str] | None = None,
    find: Any = None,
    run_command: Any = None,
    core: bool = False,
    index: Any = None,
) -> Config:
    """The configuration roslaunch resolves ``path`` to with ``args`` (``name: value``);
    ``index``: the run's package search ($(find) after ROS_PACKAGE_PATH and /usr/share)."""
    from mlaunch.ros1 import lookup

    environ = dict(os.environ if environ is None else environ)
    finder = find or lookup.package_finder(path, environ, index)
    command = run_command or lookup.command_runner(environ, os.path.abspath(path))
    return Loader(environ, finder, command).load(path, args, core)
