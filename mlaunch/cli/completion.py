"""Shell completion for bash and zsh, through argcomplete.

The shell runs ``mlaunch`` with ``_ARGCOMPLETE`` set (``register-python-argcomplete mlaunch``
installs the shell side; ./scripts/setup puts it in the venv's activate script), and
``mlaunch.cli.program`` hands over to ``complete`` here before anything else: a normal launch
never imports this module or argcomplete.

What completes where:

- the first word: subcommands (test, convert, export, ctl), package names (installed and source
  packages, as ``mlaunch PKG FILE`` finds them), and launch files and folders;
- after a package: the launch files in its share folder;
- after a launch file: ``name:=`` for each argument it declares (with its included files', as
  ``--show-args`` lists them), and ``name:=value`` for an argument with choices;
- options after ``-``, with the subcommand's own for ``mlaunch test`` and ``mlaunch export``;
- ``mlaunch ctl``: its operations, then the labels of the run it would talk to (asked over
  its control socket, as ``mlaunch ctl list``).

Completion never prints: the shell side sends stdout and stderr to /dev/null, and a launch file
that cannot be read simply completes nothing.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable, Iterable
from typing import Any

from mlaunch.app.options import build_parser
from mlaunch.commands import subcommands

# What a launch file is called (ros2 launch's pattern, and ROS 1's .launch): *launch.py,
# *launch.xml, *launch.yaml, *launch.yml, *.launch.
LAUNCH_ENDINGS = ("launch.py", "launch.xml", "launch.yaml", "launch.yml", ".launch")

Completer = Callable[..., list[str]]


def complete() -> None:
    """Answer the shell's completion request (argcomplete's protocol) and exit."""
    import argcomplete

    argcomplete.autocomplete(
        parser_for(_words()), always_complete_options=False, exclude=["-h", "--help"]
    )


def _words() -> list[str]:
    """The words of the command line before the one being completed, from ``mlaunch`` on."""
    from argcomplete.lexers import split_line

    line = os.environ.get("COMP_LINE", "")
    point = int(os.environ.get("COMP_POINT", len(line)))
    # _ARGCOMPLETE is where mlaunch's words start: 1 for mlaunch, 3 for python -m mlaunch.
    start = int(os.environ.get("_ARGCOMPLETE", "1")) - 1
    return list(split_line(line, point)[3])[start:]


def parser_for(words: list[str]) -> argparse.ArgumentParser:
    """mlaunch's parser, or a subcommand's when the line starts with one, with completers."""
    sub = subcommands().get(words[1]) if len(words) > 1 else None
    parser = sub.parser() if sub is not None else build_parser(prog="mlaunch")
    launch_target = target_completer if sub is None else launch_target_completer
    # What each positional of a parser holds, whichever subcommand's it is.
    completers: dict[str, Completer] = {
        "target": launch_target,
        "rest": rest_completer,
        "file": ros1_file_completer,
        "words": ctl_completer,
    }
    for action in parser._actions:
        if not action.option_strings and action.dest in completers:
            _set_completer(action, completers[action.dest])
        elif "--package-path" in action.option_strings:
            from argcomplete.completers import DirectoriesCompleter

            _set_completer(action, DirectoriesCompleter())
    return _nested(sub.name, parser) if sub is not None else parser


def _set_completer(action: argparse.Action, completer: Callable[..., object]) -> None:
    """argcomplete reads an action's ``completer`` attribute, which argparse does not declare."""
    setattr(action, "completer", completer)  # noqa: B010


def _nested(name: str, parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """A parser whose first word is the subcommand ``name``, then ``parser``'s arguments."""
    top = argparse.ArgumentParser(prog="mlaunch", add_help=False)
    subs = top.add_subparsers()
    subs._name_parser_map[name] = parser
    subs.choices = {name: parser}
    return top


# --- completers (argcomplete calls them with prefix=, parsed_args= and more) ---------------


def quietly(completer: Completer) -> Completer:
    """A completer that completes nothing instead of failing (a broken launch file, a race)."""

    def guarded(prefix: str = "", parsed_args: Any = None, **_: Any) -> list[str]:
        try:
            return completer(prefix, parsed_args)
        except Exception:
            return []

    guarded.__doc__ = completer.__doc__
    return guarded


@quietly
def target_completer(prefix: str, parsed_args: Any) -> list[str]:
    """The first word: subcommands, packages, launch files and folders."""
    found = [s for s in subcommands() if s.startswith(prefix)]
    if "/" not in prefix:
        found += [p for p in package_names(parsed_args) if p.startswith(prefix)]
    return found + launch_paths(prefix)


@quietly
def launch_target_completer(prefix: str, parsed_args: Any) -> list[str]:
    """A subcommand's launch target: packages, launch files and folders."""
    found = [p for p in package_names(parsed_args) if p.startswith(prefix)]
    return (found if "/" not in prefix else []) + launch_paths(prefix)


@quietly
def ros1_file_completer(prefix: str, parsed_args: Any) -> list[str]:
    """``mlaunch convert``'s file: ROS 1 launch files and folders."""
    return launch_paths(prefix, endings=(".launch", ".xml"))


@quietly
def ctl_completer(prefix: str, parsed_args: Any) -> list[str]:
    """``mlaunch ctl [RUN] OPERATION LABEL``: the operations, then the live run's labels."""
    from mlaunch.commands.ctl import WAIT_READY
    from mlaunch.parts.control import OPERATIONS

    words = list(parsed_args.words or ())
    at = next((i for i, w in enumerate(words) if w in (*OPERATIONS, WAIT_READY)), None)
    if at is None:
        return [op for op in (*OPERATIONS, WAIT_READY) if op.startswith(prefix)]
    if words[at] in ("list", WAIT_READY) or len(words) > at + 1:
        return []
    return [label for label in live_labels(words[0] if at else None) if label.startswith(prefix)]


def live_labels(run: str | None) -> list[str]:
    """The labels of the run ``mlaunch ctl`` would talk to (the newest live one by default)."""
    from mlaunch.commands.ctl import ask, find_run
    from mlaunch.parts.control_socket import PROTOCOL

    answer = ask(find_run(run, os.environ), {"version": PROTOCOL, "op": "list"})
    processes = answer.get("processes")
    return [str(p["label"]) for p in processes] if isinstance(processes, list) else []


@quietly
def rest_completer(prefix: str, parsed_args: Any) -> list[str]:
    """After the target: a package's launch files, then the file's ``name:=`` arguments."""
    target, given = parsed_args.target, [w for w in (parsed_args.rest or ()) if ":=" not in w]
    if os.path.isfile(target):
        path = target
    elif not given:
        return [f for f in package_launch_files(target, parsed_args) if f.startswith(prefix)]
    else:
        from mlaunch.ros.packages import find_launch_file

        path = find_launch_file(target, given[0])
    return argument_words(path, prefix, parsed_args)


# --- what they find ---------------------------------------------------------------------------


def _index(parsed_args: Any) -> Any:
    from mlaunch.ros.packages import index
    from mlaunch.ros.search import PackageSearch

    paths = getattr(parsed_args, "package_path", None) or []
    return index(search=PackageSearch(paths, None, os.environ), from_cwd=True)


def package_names(parsed_args: Any) -> list[str]:
    """Installed and source packages, as ``mlaunch PKG FILE`` would find them."""
    return sorted(_index(parsed_args).all_packages())


def package_launch_files(package: str, parsed_args: Any) -> list[str]:
    """The launch files' names in a package's share folder (what ``mlaunch PKG FILE`` takes)."""
    from mlaunch.ros.packages import SKIPPED_DIRS

    found = _index(parsed_args).get(package)
    names: set[str] = set()
    for _root, dirs, files in os.walk(found.share_directory):
        dirs[:] = [d for d in dirs if not d.startswith(".") and d not in SKIPPED_DIRS]
        names.update(f for f in files if f.endswith(LAUNCH_ENDINGS))
    return sorted(names)


def launch_paths(prefix: str, endings: Iterable[str] = LAUNCH_ENDINGS) -> list[str]:
    """Folders (ending in ``/``) and launch files whose path starts with ``prefix``."""
    folder, _, start = prefix.rpartition("/")
    where = folder + "/" if folder else ""
    wanted = tuple(endings)
    try:
        entries = sorted(os.scandir(os.path.expanduser(folder) if folder else "."), key=_name)
    except OSError:
        return []
    found = []
    for entry in entries:
        if not entry.name.startswith(start) or (entry.name.startswith(".") and not start):
            continue
        if entry.is_dir():
            found.append(f"{where}{entry.name}/")
        elif entry.name.endswith(wanted):
            found.append(f"{where}{entry.name}")
    return found


def _name(entry: os.DirEntry[str]) -> str:
    return entry.name


def argument_words(path: str, prefix: str, parsed_args: Any) -> list[str]:
    """``name:=`` for each argument the file declares, or ``name:=choice`` after ``name:=``."""
    infos = declared_arguments(path, parsed_args)
    name, sep, _ = prefix.partition(":=")
    if sep:
        for info in infos:
            if info.name == name and info.choices:
                return [f"{name}:={c}" for c in info.choices if f"{name}:={c}".startswith(prefix)]
        return []
    given = {w.partition(":=")[0] for w in (parsed_args.rest or ()) if ":=" in w}
    return [f"{i.name}:=" for i in infos if i.name.startswith(prefix) and i.name not in given]


def declared_arguments(path: str, parsed_args: Any) -> list[Any]:
    """The file's arguments, with its included files', as ``mlaunch FILE --show-args`` lists."""
    from mlaunch import compat, readers
    from mlaunch.resolve.resolver import collect_arguments
    from mlaunch.ros.search import PackageSearch, searching

    compat.install()
    path = os.path.abspath(path)
    search = PackageSearch(getattr(parsed_args, "package_path", None) or [], path, os.environ)
    with searching(search):
        description = readers.load(path)
        return collect_arguments(description, path=path, arguments={}, environ=os.environ)
