"""Run by /usr/bin/python3 (Debian's, with roslaunch): a launch file as the real roslaunch
resolves it, as JSON on stdout (argv: FILE [name:=value ...]). Used by the ROS 1 differential
tests, which also import ``typed`` (the same typing for both sides); it must not import
mlaunch."""

import base64
import json
import sys


def typed(value):
    if isinstance(value, bool):
        return ["bool", value]
    if isinstance(value, int):
        return ["int", value]
    if isinstance(value, float):
        return ["double", value]
    if isinstance(value, str):
        return ["str", value]
    if isinstance(value, list):
        return ["list", [typed(v) for v in value]]
    if isinstance(value, dict):
        return ["dict", {k: typed(v) for k, v in value.items()}]
    if isinstance(value, bytes):  # binfile, as mlaunch reads it
        return ["binary", base64.b64encode(value).decode()]
    if hasattr(value, "data"):  # binfile, as roslaunch reads it (xmlrpc Binary)
        return ["binary", base64.b64encode(value.data).decode()]
    return [type(value).__name__, str(value)]


def main():
    import roslaunch.config

    path, args = sys.argv[1], sys.argv[2:]
    sys.argv = ["roslaunch", path, *args]
    config = roslaunch.config.load_config_default([path], None, verbose=False)
    nodes = []
    for n in config.nodes:
        nodes.append(
            {
                "package": n.package,
                "type": n.type,
                "name": n.name,
                "namespace": n.namespace,
                "args": n.args,
                "remaps": [list(r) for r in n.remap_args],
                "env": [list(e) for e in n.env_args],
                "output": n.output,
                "cwd": n.cwd,
                "launch_prefix": n.launch_prefix,
                "required": n.required,
                "respawn": n.respawn,
                "respawn_delay": n.respawn_delay,
                "machine": n.machine_name,
            }
        )
    params = {k: typed(p.value) for k, p in config.params.items()}
    core = [n.namespace + n.name for n in config.nodes_core]
    found = {"nodes": nodes, "params": params, "clear_params": config.clear_params, "core": core}
    json.dump(found, sys.stdout)


if __name__ == "__main__":
    main()
