"""Reading a roslaunch file into the model: the tags, their scopes, and where globals land.

``read(path)`` parses the XML (roslaunch's tags, attributes and ``$(...)`` args, checked where
roslaunch checks them) and maps it to the model of the ROS 2 description it becomes
(``mlaunch.ros1.model``). Every ROS 1 -> ROS 2 decision is taken here, once; the node mapping
table is ``mlaunch.ros1.mapping.NODE_MAP``.
"""

from __future__ import annotations

import os

from mlaunch.frontends.limits import allow_deep_trees
from mlaunch.ros1.elements import Element, parse_xml
from mlaunch.ros1.mapping import NodeMapper, lower_gui
from mlaunch.ros1.model import (
    MACHINE_FIELDS,
    Cond,
    DeclareArg,
    Group,
    Include,
    Item,
    MachineItem,
    NodeItem,
    Process,
    SetArg,
    SetEnv,
    SetParam,
    SetRemap,
    Value,
    Warn,
    describe_value,
    rel_origin,
    static_text,
    text,
)
from mlaunch.ros1.params import ParamReader
from mlaunch.ros1.scope import ArgInfo, Desc, Out, Pending, Scope, Skip
from mlaunch.ros1.values import dotted, split_arguments


class Reader(ParamReader, NodeMapper):
    """Reads one roslaunch file into the model."""

    # --- the file -----------------------------------------------------------------------------

    def read(self) -> list[Item]:
        root = parse_xml(self.path)
        if root.tag != "launch":
            raise self.error(root, f"the root element must be <launch>, not <{root.tag}>")
        scope = Scope("/", {}, is_ns=True, is_root=True)
        out = Out()
        self.check_attributes(root, out)
        reason = root.attrs.get("deprecated")
        if reason is not None:
            out.decls.append(
                Warn(origin=self.origin(root), message=f"this launch file is deprecated: {reason}")
            )
        self.scope(root.children, scope, out)
        self.land(out, scope)
        for consumer in out.consumers:
            if consumer.kind == "robot_description":
                consumer.node.scope_notes.append(
                    "robot_state_publisher gets no robot_description: in ROS 1 it read the global"
                    " parameter (set in another file?); in ROS 2 it must be the node's own"
                    " parameter"
                )
        self.finish_arbotix()
        self.finish_jsp()
        items = out.items()
        lower_gui(items)
        return items

    def scope(self, elements: list[Element], scope: Scope, out: Out) -> None:
        for el in elements:
            handler = getattr(self, "tag_" + el.tag.replace("-", "_"), None)
            if handler is None:
                out.body.append(
                    Warn(
                        origin=self.origin(el),
                        message=f"unrecognized tag <{el.tag}> is ignored (as roslaunch does)",
                    )
                )
                continue
            self.check_attributes(el, out)
            handler(el, scope, out)

    def land(self, out: Out, scope: Scope) -> None:
        """Place the pending global parameters that belong to this scope; keep the others."""
        keep: list[Pending] = []
        for pending in out.pending:
            here = (pending.target == "ns" and scope.is_ns) or scope.is_root
            uses_own = bool(pending.refs & scope.own)
            if not here and not uses_own:
                keep.append(pending)
                continue
            if uses_own and not here:
                self.warn_scope(pending)
            if isinstance(pending.item, SetParam):
                out.params.append(_wrap(pending.item, pending.conds))
            else:
                self.bind(pending, out)
        out.pending = keep

    def warn_scope(self, pending: Pending) -> None:
        item = pending.item
        what = "robot_description" if isinstance(item, Desc) else describe_value(item.name)
        message = (
            f"global parameter {what} reads an <arg> of its <group>, so it stays in that group:"
            " in ROS 2 only the nodes of the group get it"
        )
        if isinstance(item, Desc):
            self.desc_notes.setdefault(item.origin, []).append(message)
        else:
            item.scope_notes.append(message)

    def bind(self, pending: Pending, out: Out) -> None:
        """Give a robot_description / use_gui global to the nodes of this scope that read it."""
        desc = pending.item
        assert isinstance(desc, Desc)
        takers = [c for c in out.consumers if c.kind == desc.kind]
        conds = set(pending.conds) | ({desc.own} if desc.own else set())
        for consumer in takers:
            node = consumer.node
            node_conds = set(consumer.conds) | ({node.condition} if node.condition else set())
            rel = rel_origin(desc.origin)
            if desc.kind == "robot_description":
                node.parameters.insert(0, (text("robot_description"), desc.value))
                where = os.path.basename(desc.origin)
                node.notes.append(f"robot_description: the global parameter of {where}")
            else:
                node.gui = desc.value
            if not conds <= node_conds:
                node.scope_notes.append(
                    f"the global {desc.kind} of {rel} is set only under a condition this node"
                    f" does not share; in ROS 2 the node gets it whenever it runs"
                )
            node.scope_notes.extend(self.desc_notes.get(desc.origin, []))
        out.consumers = [c for c in out.consumers if c.kind != desc.kind]
        if takers:
            return
        if desc.kind == "use_gui":  # no joint_state_publisher here: an ordinary global
            item = SetParam(
                origin=desc.origin, condition=desc.own, name=text("use_gui"), value=desc.value
            )
            out.params.append(_wrap(item, pending.conds))
            return
        out.params.append(
            Warn(
                origin=desc.origin,
                condition=desc.own,
                scope_note=True,
                message="robot_description is set, but no robot_state_publisher of this file's"
                " scope takes it: ROS 2 has no parameter server, so it reaches no node (give it"
                " to the node that needs it as a parameter)",
            )
        )

    def pass_up(self, inner: Out, out: Out, cond: Cond | None) -> None:
        """What a child scope leaves for its parent, under the child's condition."""
        extra = (cond,) if cond is not None else ()
        for pending in inner.pending:
            pending.conds = (*extra, *pending.conds)
            out.pending.append(pending)
        for consumer in inner.consumers:
            consumer.conds = (*extra, *consumer.conds)
            out.consumers.append(consumer)

    # --- tags ---------------------------------------------------------------------------------

    def tag_arg(self, el: Element, scope: Scope, out: Out) -> None:
        name = self.literal(el, "name", scope, required=True)
        assert name is not None
        default = self.attr(el, "default", scope)
        value = self.attr(el, "value", scope)
        if default is not None and value is not None:
            raise self.error(el, "<arg> tag must have one and only one of value/default")
        cond = self.condition(el, scope)
        known = scope.args.get(name)
        if known is not None and cond is None and not known.constant and name in scope.own:
            raise self.error(el, f"arg {name!r} has already been declared")
        doc = el.attrs.get("doc")
        item: Item
        if value is not None:
            item = SetArg(origin=self.origin(el), condition=cond, name=name, value=value)
        else:
            item = DeclareArg(
                origin=self.origin(el), condition=cond, name=name, default=default, doc=doc
            )
        scope.args[name] = ArgInfo(value if value is not None else default, value is not None)
        scope.own.add(name)
        out.decls.append(item)

    def tag_remap(self, el: Element, scope: Scope, out: Out) -> None:
        src = self.attr(el, "from", scope, required=True)
        dst = self.attr(el, "to", scope, required=True)
        assert src is not None and dst is not None
        cond = self.condition(el, scope)
        out.body.append(SetRemap(origin=self.origin(el), condition=cond, src=src, dst=dst))

    def tag_env(self, el: Element, scope: Scope, out: Out) -> None:
        name = self.attr(el, "name", scope, required=True)
        value = self.attr(el, "value", scope, required=True)
        assert name is not None and value is not None
        cond = self.condition(el, scope)
        out.body.append(SetEnv(origin=self.origin(el), condition=cond, name=name, value=value))

    def tag_group(self, el: Element, scope: Scope, out: Out) -> None:
        cond = self.condition(el, scope)
        ns = self.attr(el, "ns", scope)
        inner_scope = scope.child(static_text(ns) if ns else None, ns is not None)
        inner = Out()
        self.scope(el.children, inner_scope, inner)
        self.land(inner, inner_scope)
        group = Group(origin=self.origin(el), condition=cond, items=inner.items(), namespace=ns)
        if "clear_params" in el.attrs:
            group.warnings.append(_CLEAR_PARAMS)
        if group.items:
            out.body.append(group)
        elif group.warnings:  # nothing left in it (its parameters moved out): only the warning
            out.body.append(Warn(origin=group.origin, condition=cond, message=_CLEAR_PARAMS))
        self.pass_up(inner, out, cond)

    def tag_include(self, el: Element, scope: Scope, out: Out) -> None:
        path = self.attr(el, "file", scope, required=True)
        assert path is not None
        cond = self.condition(el, scope)
        ns = self.attr(el, "ns", scope)
        arguments: list[tuple[str, Value]] = []
        envs: list[Item] = []
        notes: list[str] = []
        for child in el.children:
            if child.tag == "arg":
                self.check_attributes(child, out)
                if self.condition(child, scope) is not None:
                    notes.append(
                        f"<arg> at line {child.line}: if/unless on an <include>'s <arg> is not"
                        " supported by ROS 2 launch arguments: it is always passed"
                    )
                name = self.literal(child, "name", scope, required=True)
                value = self.attr(child, "value", scope) or self.attr(child, "default", scope)
                if value is None:
                    raise self.error(child, f"<arg name={name!r}> of an <include> needs a value")
                assert name is not None
                arguments.append((name, value))
            elif child.tag == "env":
                self.check_attributes(child, out)
                self.tag_env(child, scope, _collect := Out())
                envs += _collect.body
            else:
                raise self.error(child, f"<{child.tag}> is not valid inside <include>")
        if "pass_all_args" in el.attrs and self.flag(el, "pass_all_args", scope) is not False:
            # roslaunch passes every arg the including file has (its own <arg>s win). ROS 2's
            # include checks its required arguments against those it is given by name, so
            # each is given as itself: $(arg x) for x.
            given = {name for name, _ in arguments}
            for name in sorted(set(scope.args) - given):
                arguments.append((name, self.value(f"$(arg {name})", el, "pass_all_args", scope)))
        include = Include(origin=self.origin(el), path=path, arguments=arguments, warnings=notes)
        if "clear_params" in el.attrs:
            include.warnings.append(_CLEAR_PARAMS)
        if ns is None and not envs:
            include.condition = cond
            out.body.append(include)
            return
        group = Group(origin=self.origin(el), condition=cond, items=[*envs, include])
        group.namespace = ns
        out.body.append(group)

    def tag_test(self, el: Element, scope: Scope, out: Out) -> None:
        name = el.attrs.get("test-name", el.attrs.get("type", "?"))
        out.body.append(
            Warn(
                origin=self.origin(el),
                message=f"rostest <test test-name={name!r}> is skipped: it runs under rostest,"
                " not a launch (ROS 2: launch_testing)",
            )
        )

    def tag_machine(self, el: Element, scope: Scope, out: Out) -> None:
        item = MachineItem(
            origin=self.origin(el),
            condition=self.condition(el, scope),
            name=self.attr(el, "name", scope, required=True) or (),
            address=self.attr(el, "address", scope, required=True) or (),
        )
        for field_name, attr_name in MACHINE_FIELDS:
            setattr(item, field_name, self.attr(el, attr_name, scope))
        if "password" in el.attrs:
            item.warnings.append(
                "<machine password> is ignored: mlaunch's ssh never prompts (BatchMode); use a key"
            )
        for old in ("ros-root", "ros-package-path", "ros-ip", "ros-host-name"):
            if old in el.attrs:
                item.warnings.append(f"<machine {old}> is ignored: use env-loader")
        out.body.append(item)

    def tag_master(self, el: Element, scope: Scope, out: Out) -> None:
        out.body.append(
            Warn(origin=self.origin(el), message="<master> is ignored: ROS 2 has no master")
        )

    # --- nodes --------------------------------------------------------------------------------

    def tag_node(self, el: Element, scope: Scope, out: Out) -> None:
        cond = self.condition(el, scope)
        node = NodeItem(
            origin=self.origin(el),
            condition=cond,
            package=self.attr(el, "pkg", scope, required=True) or (),
            executable=self.attr(el, "type", scope, required=True) or (),
            name=self.attr(el, "name", scope, required=True),
            namespace=self.attr(el, "ns", scope),
            output=self.output(el, scope),
            prefix=self.attr(el, "launch-prefix", scope),
            machine=self.attr(el, "machine", scope),
        )
        args = self.attr(el, "args", scope, program=False)
        node.arguments = split_arguments(args) if args is not None else []
        if args is not None and static_text(args) is None:
            node.shell_args = args
        self.process_attributes(node, el, scope)
        self.node_children(node, el, scope, out)
        for attr_name, why in (("cwd", _CWD), ("clear_params", _CLEAR_PARAMS)):
            if attr_name in el.attrs:
                node.warnings.append(why.format(value=el.attrs[attr_name]))
        out.body.extend(self.map_node(node, el, out))

    def output(self, el: Element, scope: Scope) -> Value | None:
        value = self.attr(el, "output", scope)
        found = static_text(value)
        if found is not None and found not in ("log", "screen"):
            raise self.error(el, f"output={found!r} is not valid; valid: log, screen")
        return value

    def process_attributes(self, node: Process, el: Element, scope: Scope) -> None:
        respawn = self.flag(el, "respawn", scope)
        required = self.flag(el, "required", scope)
        if respawn is True and required is True:
            raise self.error(el, "respawn and required cannot both be set to true")
        node.respawn = False if respawn is None else respawn
        node.required = False if required is None else required
        delay = self.attr(el, "respawn_delay", scope)
        found = static_text(delay)
        if found is not None:
            try:
                node.respawn_delay = float(found)
            except ValueError:
                raise self.error(el, f"respawn_delay={found!r} is not a number of seconds")
        else:
            node.respawn_delay = delay

    def node_children(self, node: NodeItem, el: Element, scope: Scope, out: Out) -> None:
        for child in el.children:
            if child.tag not in ("param", "rosparam", "remap", "env"):
                out.body.append(
                    Warn(
                        origin=self.origin(child),
                        message=f"<{child.tag}> is not valid inside <node> and is ignored (as"
                        " roslaunch does); valid: param, rosparam, remap, env",
                    )
                )
                continue
            self.check_attributes(child, out)
            if self.condition(child, scope) is not None:
                node.warnings.append(
                    f"<{child.tag}> at line {child.line}: if/unless inside a node is not"
                    " supported by ROS 2 node parameters: it always applies"
                )
            try:
                self.node_child(node, child, scope, out)
            except Skip as skip:
                node.warnings.append(f"<{child.tag}> at line {child.line}: {skip.message}")
            finally:
                for message in self.drain_unheld():
                    node.warnings.append(f"<{child.tag}> at line {child.line}: {message}")

    def node_child(self, node: NodeItem, child: Element, scope: Scope, out: Out) -> None:
        if child.tag == "remap":
            src = self.attr(child, "from", scope, required=True)
            dst = self.attr(child, "to", scope, required=True)
            assert src is not None and dst is not None
            node.remappings.append((src, dst))
        elif child.tag == "env":
            env_name = self.attr(child, "name", scope, required=True)
            env_value = self.attr(child, "value", scope, required=True)
            assert env_name is not None and env_value is not None
            node.env.append((env_name, env_value))
        else:
            entries = (
                self.param_entries(child, scope)
                if child.tag == "param"
                else self.rosparam_entries(child, scope)
            )
            for name, value in entries:
                plain = static_text(name)
                if plain is not None and plain.startswith("/"):
                    self.global_param(name, value, None, child, scope, out)
                    continue
                if plain is not None:
                    name = text(dotted(plain.lstrip("~")))
                node.parameters.append((name, value))


_CLEAR_PARAMS = (
    "clear_params has no effect in ROS 2: there is no parameter server, a node only has the"
    " parameters this launch gives it"
)
_CWD = (
    "cwd={value!r} is not kept: ROS 2 starts nodes in the launcher's working directory"
    " (ROS 1 used ROS_HOME)"
)


def _wrap(item: Item, conds: tuple[Cond, ...]) -> Item:
    """An item under the conditions of the groups it was hoisted out of (unscoped groups)."""
    for cond in reversed(conds):
        item = Group(origin=item.origin, condition=cond, items=[item], scoped=False)
    return item


def read(path: str, converting: bool = False) -> list[Item]:
    """The ROS 2 description (as the model) a roslaunch file maps to.

    ``converting``: the description is written out for another machine, so what is installed
    here must not decide what it contains (static transforms stay live nodes).
    """
    allow_deep_trees()  # reading, building and converting the model are recursive walks
    reader = Reader(path)
    reader.converting = converting
    return reader.read()
