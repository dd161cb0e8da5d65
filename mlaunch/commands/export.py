"""``mlaunch export FILE [name:=value ...] --to systemd DIR``: hand a launch to the system's init.

The launch is resolved exactly as ``mlaunch FILE`` would resolve it (same arguments, options and
environment), then written out by a format's writer (systemd: mlaunch.export.systemd). Nothing
is started.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from mlaunch.export.bundle import check_portable, stem
from mlaunch.plan.argparser import ArgumentParser
from mlaunch.plan.errors import MlaunchError, UsageError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.app.options import Options
    from mlaunch.export.systemd import Export, Unit
    from mlaunch.plan.steps import Deferred, Plan

FORMATS = ("systemd", "ansible")
USAGE = (
    "mlaunch export FILE [name:=value ...] --to systemd|ansible DIR [--name NAME] [--user USER]"
    " [--env NAME[=VALUE]]... [--allow-standins]"
)


def parse(args: list[str]) -> tuple[argparse.Namespace, list[str]]:
    """(export settings, the rest: the launch target, its arguments and mlaunch's options)."""
    return build_parser().parse_known_args(args)


def build_parser() -> argparse.ArgumentParser:
    """``mlaunch export``'s own options (the rest are mlaunch FILE's)."""
    parser = ArgumentParser(prog="mlaunch export", usage=USAGE, add_help=True)
    parser.add_argument(
        "--to",
        nargs=2,
        metavar=("FORMAT", "DIR"),
        required=True,
        help="what to write and where: 'systemd DIR' writes units, params files and a README;"
        " 'ansible DIR' a playbook folder (deploy.yml, teardown.yml, an example inventory.yml)",
    )
    parser.add_argument("--name", help="the target's name and the units' prefix (default: FILE)")
    parser.add_argument("--user", help="the user the services run as (User=; default: root)")
    parser.add_argument(
        "--install-dir",
        help="where DIR will be on the robot (the units name their files there; default: DIR)",
    )
    parser.add_argument(
        "--env",
        action="append",
        default=[],
        metavar="NAME[=VALUE]",
        help="put NAME (a shell pattern such as 'ROS_*' picks several) from this environment, or"
        " NAME=VALUE, into NAME.env for every unit; nothing else of this environment is exported",
    )
    parser.add_argument("--force", action="store_true", help="write into a non-empty DIR")
    parser.add_argument(
        "--allow-standins",
        action="store_true",
        help="export even when processes run mlaunch's stand-ins or programs of this computer's"
        " virtual environment (each is named; without this the export is refused)",
    )
    return parser


def command(args: Sequence[str]) -> int:
    """``mlaunch export``'s work; errors go up to mlaunch.cli.main."""
    from mlaunch.app.options import parse_options

    try:
        settings, rest = parse(list(args))
    except SystemExit as e:  # argparse: --help (0) or a usage error (2), already printed
        return int(e.code or 0)
    fmt, out_dir = settings.to
    if fmt not in FORMATS:
        raise UsageError(f"--to {fmt!r} is not a format; valid: {', '.join(FORMATS)}")
    if not rest:
        raise UsageError(f"a launch file is needed: {USAGE}")
    try:
        opts = parse_options(rest)
    except SystemExit as e:
        return int(e.code or 0)
    if fmt == "ansible":
        from mlaunch.export.ansible import export_ansible

        return export_ansible(opts, settings, out_dir)
    return export_systemd(opts, settings, out_dir)


def export_systemd(opts: Options, settings: argparse.Namespace, out_dir: str) -> int:
    from mlaunch.app import pipeline
    from mlaunch.engine.privatedir import private_temp_dir, remove_private_dir
    from mlaunch.export import systemd
    from mlaunch.export.folder import Folder
    from mlaunch.resolve.resolver import resolve_deferred

    if os.path.lexists(out_dir):  # refused now, before loading the file
        Folder.open(out_dir, force=settings.force).close()
    path, description = pipeline.load_target(opts)
    prefix = systemd.unit_name(settings.name or stem(path))
    temp_dir = private_temp_dir()
    try:
        plan, options, labels = pipeline.resolve_for_run(
            opts, path, description, temp_dir=temp_dir, log_dir=""
        )

        def expand(body: Deferred) -> Plan | None:
            try:
                return resolve_deferred(body, labels=labels, options=options)
            except Exception as e:  # a handler's Python code, called here with no event
                export.warnings.append(
                    f"{getattr(body, 'origin', '') or '?'}: not exported ({type(e).__name__}: {e})"
                )
                return None

        export = systemd.Export(plan, prefix=prefix, expand=expand)
        units = export.build()
        if not units:
            raise MlaunchError(f"{path}: the launch starts no process; nothing to export")
        check_portable([u.spec for u in units], settings.allow_standins, export.warnings)
        write_units(export, units, out_dir, settings, path, prefix, opts.arguments)
    finally:
        remove_private_dir(temp_dir)
    for warning in export.warnings:
        print(f"mlaunch export: warning: {warning}", file=sys.stderr)
    from mlaunch.engine.lifeline import write_stdout

    write_stdout(
        f"wrote {len(units)} services, {prefix}.target and {prefix}.service (the whole launch"
        f" under mlaunch) to {out_dir} (see README.md)\n"
    )
    return 0


def write_units(
    export: Export,
    units: list[Unit],
    out_dir: str,
    settings: argparse.Namespace,
    source: str,
    prefix: str,
    arguments: dict[str, str],
) -> None:
    from mlaunch.export import systemd
    from mlaunch.export.bundle import copy_launch_tree, mlaunch_command

    install_dir = os.path.abspath(settings.install_dir or out_dir)
    copies = systemd.install_params(units, install_dir)
    env_file = os.path.join(install_dir, f"{prefix}.env")
    # Only what --env names: the caller's environment holds tokens and keys and paths of the
    # machine that exported; what the launch changed is in each unit's Environment=.
    chosen = systemd.chosen_environment(settings.env, os.environ)
    if not chosen and any(unit.spec.node is not None for unit in units):
        export.warnings.append(
            f"{prefix}.env is empty: the nodes get systemd's environment, not this one; add what"
            " they need with --env (e.g. --env AMENT_PREFIX_PATH --env LD_LIBRARY_PATH"
            " --env PYTHONPATH --env 'ROS_*')"
        )
    cwd = os.getcwd()
    texts = {
        unit.name: systemd.service_text(
            unit, target=f"{prefix}.target", env_file=env_file, cwd=cwd, user=settings.user
        )
        for unit in units
    }  # every unit is checked before any file is written
    target = systemd.target_text(units, os.path.basename(source))
    launch = os.path.join(install_dir, "launch", os.path.basename(source))
    command = [*mlaunch_command(os.environ.get("PATH", os.defpath)), launch]
    command += [f"{name}:={value}" for name, value in arguments.items()]
    launch_service = systemd.launch_service_text(
        units,
        command,
        target=f"{prefix}.target",
        env_file=env_file,
        cwd=cwd,
        user=settings.user,
        description=os.path.basename(source),
    )
    environment = systemd.environment_file(chosen).encode()
    from mlaunch.export.folder import Folder

    folder = Folder.open(out_dir, force=settings.force)
    try:
        folder.write(f"{prefix}.env", environment, 0o600)  # secrets: the owner's alone
        params = folder.subfolder("params") if copies else None
        for source_file, name in copies:
            assert params is not None
            with open(source_file, "rb") as f:
                params.write(name, f.read(), 0o600)
        if params is not None:
            params.close()
        for name, text in texts.items():
            folder.write(name, text.encode("utf-8"), 0o644)
        folder.write(f"{prefix}.target", target.encode("utf-8"), 0o644)
        folder.write(f"{prefix}.service", launch_service.encode("utf-8"), 0o644)
        copy_launch_tree(source, folder, "launch", export_root=out_dir)
        readme = systemd.readme_text(prefix, install_dir, os.path.basename(source), export.warnings)
        folder.write("README.md", readme.encode("utf-8"), 0o644)
    finally:
        folder.close()
