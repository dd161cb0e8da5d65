"""Write down the Python names and keyword arguments of the reference launch (run under its python).

    bash -c 'source REFERENCE/env.sh && python tests/conformance/jazzy_python_api.py' > mlaunch/check/jazzy_python.json  # REFERENCE: tests/reference.py

The output (mlaunch/check/jazzy_python.json) is data the portability check holds .launch.py files to (which
``launch``/``launch_ros`` modules exist, what names they export, which keyword arguments their
classes take). test_portability checks that the file still says what the reference has.
"""

from __future__ import annotations

import importlib
import inspect
import json
import pkgutil
import warnings

PACKAGES = ("launch", "launch_ros", "launch_xml", "launch_yaml")
# The modules launch files import names from: their names and classes are written down.
IMPORTED = (
    "launch",
    "launch.actions",
    "launch.conditions",
    "launch.event_handlers",
    "launch.events",
    "launch.events.process",
    "launch.launch_description_sources",
    "launch.substitutions",
    "launch.utilities",
    "launch_ros",
    "launch_ros.actions",
    "launch_ros.descriptions",
    "launch_ros.event_handlers",
    "launch_ros.events",
    "launch_ros.events.lifecycle",
    "launch_ros.parameter_descriptions",
    "launch_ros.substitutions",
    "launch_ros.utilities",
    "launch_xml.launch_description_sources",
    "launch_yaml.launch_description_sources",
)


def modules() -> list[str]:
    out = []
    for package in PACKAGES:
        root = importlib.import_module(package)
        out.append(package)
        for info in pkgutil.walk_packages(root.__path__, prefix=package + "."):
            if ".test" not in info.name and "conftest" not in info.name:
                out.append(info.name)
    return sorted(out)


def keywords(cls: type) -> list[str] | None:
    """Keyword arguments the constructor takes, following **kwargs up the MRO; None: any."""
    names: set[str] = set()
    for klass in cls.__mro__:
        init = klass.__dict__.get("__init__")
        if init is None:
            continue
        if klass is object:
            break
        try:
            params = inspect.signature(init).parameters.values()
        except (TypeError, ValueError):
            return None
        forwards = False
        for p in params:
            if p.kind is p.VAR_KEYWORD:
                forwards = True
            elif p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.name != "self":
                names.add(p.name)
        if not forwards:
            return sorted(names)
    return sorted(names)


def main() -> None:
    warnings.simplefilter("ignore")
    exports: dict[str, list[str]] = {}
    classes: dict[str, list[str] | None] = {}
    for name in IMPORTED:
        module = importlib.import_module(name)
        public = sorted(n for n in dir(module) if not n.startswith("_"))
        exports[name] = public
        for attr in public:
            value = getattr(module, attr)
            if inspect.isclass(value) and value.__module__.split(".")[0] in PACKAGES:
                classes[f"{name}.{attr}"] = keywords(value)
    data = {"modules": modules(), "exports": exports, "keywords": classes}
    print(json.dumps(data, indent=1, sort_keys=True))


if __name__ == "__main__":
    main()
