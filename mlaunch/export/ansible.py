"""``mlaunch export FILE --to ansible DIR``: a self-contained playbook folder for a fleet.

    DIR/deploy.yml     copy the launch to each host, start it under the host's supervisor,
                       wait until it is ready (``mlaunch ctl wait-ready``), report per host
    DIR/teardown.yml   stop it and remove what deploy put there
    DIR/inventory.yml  an example inventory (every variable the plays read)
    DIR/export.yml     what the export fixed: the launch's name, file and arguments
    DIR/files/launch/  the launch file's folder (includes, parameter files, URDFs next to it)
    DIR/README.md      the three commands, the variables, what a host needs installed

Ansible is the engine (hosts, SSH, parallelism, check mode, reports); mlaunch only writes plays
that use its builtin modules. Each host gets a folder of its own under ``install_root`` named by
its inventory name, and runs the launch there with its own ROS log folder, so several inventory
hosts on one computer (a simulated fleet) never see each other's run. The supervisor is systemd
(``--user``, or the system's as root) when PID 1 is systemd, else mlaunch itself, detached, with
its guard (mlaunch kills what it started when it is killed). Idempotent: a host whose launch is
up with the same files and arguments is left alone; a change of either restarts it.

A launch that declares machines is split by machine: the example inventory has one host per
share (each machine with processes, and ``local`` for those given no machine), and each host
runs only its share (``mlaunch FILE --machine SHARE``, mlaunch.resolve.shares).
"""

from __future__ import annotations

import json
import os
import shlex
import sys

from mlaunch.export.bundle import check_portable, copy_launch_tree, stem
from mlaunch.plan.errors import MlaunchError, UsageError
from mlaunch.plan.machine import LOCAL_SHARE

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    import argparse

    from mlaunch.app.options import Options
    from mlaunch.plan.machine import MachineSpec
    from mlaunch.plan.steps import ProcessSpec

# The plays, as mlaunch ships them (mlaunch/export/playbook/), copied into the export.
PLAYBOOK = os.path.join(os.path.dirname(os.path.abspath(__file__)), "playbook")
PLAYBOOK_FILES = ("deploy.yml", "teardown.yml", "vars.yml", "tasks/facts.yml", "tasks/stop.yml")


def inventory_text(name: str, shares: dict[str, MachineSpec | None] | None = None) -> str:
    """The example inventory: two robots; for a launch split by machine, one host per share
    (named by its machine, with its address, user and ssh port as the machine says them)."""
    hosts: dict[str, dict[str, object]] = {
        "robot1": {"ansible_host": "192.0.2.11", "launch_arguments": {}},
        "robot2": {"ansible_host": "192.0.2.12", "launch_arguments": {}},
    }
    if shares:
        hosts = {share: _host_vars(machine) for share, machine in shares.items()}
    example = {
        "all": {
            "hosts": hosts,
            "vars": {
                "mlaunch": "mlaunch",
                "install_root": "mlaunch-fleet",
                "ready_timeout": 60,
                "launch_environment": {"ROS_DOMAIN_ID": "0"},
            },
        }
    }
    head = (
        f"# An example inventory for {name} (mlaunch export). Every variable is optional:\n"
        "#   mlaunch             the command that runs mlaunch on the host (default: mlaunch)\n"
        "#   install_root        where each host's folder goes, relative to the login's home\n"
        "#                       (default: mlaunch-fleet); the folder is ROOT/NAME/HOST\n"
        "#   launch_arguments    name: value, over the export's arguments (export.yml)\n"
        "#   launch_environment  variables the launch runs with (ROS_DOMAIN_ID, ...)\n"
        "#   ready_timeout       seconds wait-ready waits (default: 60)\n"
        "#   supervisor          detached | systemd-user | systemd-system (default: found)\n"
    )
    if shares:
        head += (
            "#   mlaunch_machine     the share of the launch the host runs (mlaunch --machine):\n"
            "#                       a machine of the launch, or 'local' for the processes given\n"
            "#                       no machine (default: the host's inventory name)\n"
            "# One host per machine of the launch, each running only its processes; their\n"
            "# address, user and ssh port as the launch declares the machine. 'local' runs the\n"
            "# processes given no machine: set its address (192.0.2.10 is a placeholder), or\n"
            "# ansible_connection: local to run them where ansible-playbook runs.\n"
        )
    return head + json.dumps(example, indent=2) + "\n"


def _host_vars(machine: MachineSpec | None) -> dict[str, object]:
    if machine is None:  # the local share: the computer that launched before the split
        return {"ansible_host": "192.0.2.10", "mlaunch_machine": LOCAL_SHARE}
    out: dict[str, object] = {"ansible_host": machine.address}
    if machine.user:
        out["ansible_user"] = machine.user
    if machine.ssh_port:
        out["ansible_port"] = machine.ssh_port
    out["mlaunch_machine"] = machine.name
    return out


def shares_of(
    specs: list[ProcessSpec], declared: dict[str, MachineSpec]
) -> dict[str, MachineSpec | None]:
    """The shares of a launch with machines, each with its machine (None for ``local``), in the
    order of their first process; empty for a launch without machines (it is not split)."""
    if not declared:
        return {}
    out: dict[str, MachineSpec | None] = {}
    for spec in specs:
        share = LOCAL_SHARE if spec.machine is None else spec.machine.name
        out.setdefault(share, None if spec.machine is None else declared.get(share, spec.machine))
    return out


def export_text(
    name: str,
    launch: str,
    arguments: dict[str, str],
    specs: list[ProcessSpec],
    shares: list[str] | None = None,
) -> str:
    ladder = max((s.sigterm_timeout + s.sigkill_timeout for s in specs), default=10.0)
    data = {
        "mlaunch_export": {
            "name": name,
            "launch": launch,
            "arguments": arguments,
            "stop_seconds": round(ladder + 10.0, 3),
            "start_seconds": 120,
            # a launch with machines: each host runs one of these (mlaunch --machine)
            "shares": shares or [],
        }
    }
    head = "# Written by mlaunch export: what the export fixed (the plays read it).\n"
    return head + json.dumps(data, indent=2) + "\n"


def readme_text(
    name: str, launch: str, out_dir: str, warnings: list[str], shares: list[str] | None = None
) -> str:
    where = shlex.quote(out_dir)
    lines = [
        f"# {name}: {launch} for a fleet, through Ansible",
        "",
        "Written by `mlaunch export --to ansible`. Edit inventory.yml (your hosts), then:",
        "",
        f"    cd {where}",
        "    ansible-playbook -i inventory.yml deploy.yml      # --check shows what would change",
        "    ansible-playbook -i inventory.yml teardown.yml",
        "",
        "deploy.yml copies files/launch/ to each host's folder (ROOT/NAME/HOST), starts the"
        " launch under systemd (a Type=notify unit: started means ready) or, without systemd,"
        " under mlaunch detached, and waits with `mlaunch ctl wait-ready`: a host whose launch"
        " is not ready in time, or dies, fails. A second run changes nothing on a host that is"
        " up; new files or arguments restart it. teardown.yml stops it and removes the folder.",
        "",
        "Each host needs: Python 3 (for Ansible), mlaunch (the `mlaunch` variable says which),"
        " the ROS 2 packages the launch runs, and the environment to find them"
        " (`launch_environment`).",
    ]
    if shares:
        lines += [
            "",
            f"The launch declares machines, so it is split by machine: inventory.yml lists one"
            f" host per share ({', '.join(shares)}), each running only its own processes"
            " (`mlaunch FILE --machine SHARE`; the host variable `mlaunch_machine`, by default"
            " the host's inventory name), with the address, user and ssh port the launch gives"
            " the machine. `local` runs the processes given no machine. The hosts share one ROS"
            " graph through `launch_environment` (the same ROS_DOMAIN_ID on each).",
        ]
    if warnings:
        lines += ["", "## Warnings", ""] + [f"- {w}" for w in warnings]
    return "\n".join(lines) + "\n"


def export_ansible(opts: Options, settings: argparse.Namespace, out_dir: str) -> int:
    """Resolve as ``mlaunch FILE`` would (to check what it runs), then write the folder."""
    from mlaunch.app import pipeline
    from mlaunch.engine.lifeline import write_stdout
    from mlaunch.engine.privatedir import private_temp_dir, remove_private_dir
    from mlaunch.export.folder import Folder
    from mlaunch.export.systemd import unit_name

    if os.path.lexists(out_dir):  # refused now, before loading the file
        Folder.open(out_dir, force=settings.force).close()
    if settings.user or settings.env or settings.install_dir:
        raise UsageError(
            "--user, --env and --install-dir are systemd's; with --to ansible the inventory says"
            " them (ansible_user, launch_environment, install_root)"
        )
    path, description = pipeline.load_target(opts)
    name = unit_name(settings.name or stem(path))
    temp_dir = private_temp_dir()
    try:
        plan, _options, labels = pipeline.resolve_for_run(
            opts, path, description, temp_dir=temp_dir, log_dir=""
        )
    finally:
        remove_private_dir(temp_dir)
    specs = plan.processes()
    if not specs:
        raise MlaunchError(f"{path}: the launch starts no process; nothing to export")
    warnings = list(plan.warnings)
    check_portable(specs, settings.allow_standins, warnings)
    declared: dict[str, MachineSpec] = labels.run_state.get("machines") or {}
    if LOCAL_SHARE in declared:
        raise MlaunchError(
            f"{path}: the launch declares a machine named {LOCAL_SHARE!r}, which names the"
            " processes given no machine in a split by machine; rename that machine",
            where=declared[LOCAL_SHARE].origin or None,
        )
    shares = shares_of(specs, declared)
    unused = sorted(set(declared) - set(shares))
    if unused:
        warnings.append(
            f"machine(s) {', '.join(unused)} start no process at launch: no host of the"
            " inventory runs them (a process a timer or a handler starts there later runs"
            " in its machine's share: add a host with mlaunch_machine set to it)"
        )
    launch = os.path.basename(path)
    texts = {name: _read(os.path.join(PLAYBOOK, name)) for name in PLAYBOOK_FILES}
    texts |= {
        "inventory.yml": inventory_text(name, shares),
        "export.yml": export_text(name, launch, dict(opts.arguments), specs, list(shares)),
        "README.md": readme_text(name, launch, out_dir, warnings, list(shares)),
    }
    folder = Folder.open(out_dir, force=settings.force)
    try:
        files = folder.subfolder("files", 0o755)
        try:
            copy_launch_tree(path, files, "launch", export_root=out_dir)
        finally:
            files.close()
        tasks = folder.subfolder("tasks", 0o755)
        try:
            for file, text in texts.items():
                where, name = (tasks, file[6:]) if file.startswith("tasks/") else (folder, file)
                where.write(name, text.encode("utf-8"), 0o644)
        finally:
            tasks.close()
    finally:
        folder.close()
    for warning in warnings:
        print(f"mlaunch export: warning: {warning}", file=sys.stderr)
    write_stdout(
        f"wrote deploy.yml, teardown.yml and inventory.yml for {launch} to {out_dir}"
        " (see README.md)\n"
    )
    return 0


def _read(path: str) -> str:
    with open(path, encoding="utf-8") as f:
        return f.read()
