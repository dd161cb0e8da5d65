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
"""

from __future__ import annotations

import json
import os
import shlex
import sys

from mlaunch.export.bundle import check_portable, copy_launch_tree, stem
from mlaunch.plan.errors import MlaunchError, UsageError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    import argparse

    from mlaunch.app.options import Options
    from mlaunch.plan.steps import ProcessSpec

# The plays, as mlaunch ships them (mlaunch/export/playbook/), copied into the export.
PLAYBOOK = os.path.join(os.path.dirname(os.path.abspath(__file__)), "playbook")
PLAYBOOK_FILES = ("deploy.yml", "teardown.yml", "vars.yml", "tasks/facts.yml", "tasks/stop.yml")


def inventory_text(name: str) -> str:
    example = {
        "all": {
            "hosts": {
                "robot1": {"ansible_host": "192.0.2.11", "launch_arguments": {}},
                "robot2": {"ansible_host": "192.0.2.12", "launch_arguments": {}},
            },
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
    return head + json.dumps(example, indent=2) + "\n"


def export_text(name: str, launch: str, arguments: dict[str, str], specs: list[ProcessSpec]) -> str:
    ladder = max((s.sigterm_timeout + s.sigkill_timeout for s in specs), default=10.0)
    data = {
        "mlaunch_export": {
            "name": name,
            "launch": launch,
            "arguments": arguments,
            "stop_seconds": round(ladder + 10.0, 3),
            "start_seconds": 120,
        }
    }
    head = "# Written by mlaunch export: what the export fixed (the plays read it).\n"
    return head + json.dumps(data, indent=2) + "\n"


def readme_text(name: str, launch: str, out_dir: str, warnings: list[str]) -> str:
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
        plan, _options, _labels = pipeline.resolve_for_run(
            opts, path, description, temp_dir=temp_dir, log_dir=""
        )
    finally:
        remove_private_dir(temp_dir)
    specs = plan.processes()
    if not specs:
        raise MlaunchError(f"{path}: the launch starts no process; nothing to export")
    warnings = list(plan.warnings)
    check_portable(specs, settings.allow_standins, warnings)
    machines = sorted(
        {s.machine.name for s in specs if s.machine is not None and not s.machine.local}
    )
    if machines:
        # Each host would run the whole launch, SSH to the machines included: twice with two.
        warnings.append(
            f"the launch declares machines ({', '.join(machines)}): each host it is deployed to"
            " runs the whole launch and starts their processes over SSH itself, so deploy it to"
            " one host (-e hosts=NAME); the plays do not split a launch by machine"
        )
    launch = os.path.basename(path)
    texts = {name: _read(os.path.join(PLAYBOOK, name)) for name in PLAYBOOK_FILES}
    texts |= {
        "inventory.yml": inventory_text(name),
        "export.yml": export_text(name, launch, dict(opts.arguments), specs),
        "README.md": readme_text(name, launch, out_dir, warnings),
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
