"""Pure tests of package lookup: the ament index, source packages, precedence, find_launch_file.

Everything is built in tmp_path: fake ament prefixes (the resource-index marker files) and
source trees (folders with package.xml). No ROS installation is used or needed.
"""

from __future__ import annotations

import os
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest

from mlaunch import readers
from mlaunch.launch.actions import LaunchDescription, LogInfo
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.substitutions import perform
from mlaunch.launch_ros.substitutions import FindPackagePrefix, FindPackageShare
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.steps import Log
from mlaunch.resolve.resolver import ResolveOptions, resolve
from mlaunch.ros import ament_index, packages
from mlaunch.ros.packages import PackageNotFoundError
from mlaunch.ros.search import PackageSearch, searching

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(autouse=True)
def _fresh_packages() -> Iterator[None]:
    packages.forget_scans()
    yield
    packages.forget_scans()


def installed(prefix: Path, *names: str) -> Path:
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True, exist_ok=True)
    for name in names:
        (index / name).write_text("")
        (prefix / "share" / name).mkdir(parents=True, exist_ok=True)
    return prefix


def source(folder: Path, name: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="3">\n  <name> {name} </name>\n'
        "  <version>0.0.1</version>\n</package>\n"
    )
    return folder


def env(*prefixes: Path, **extra: str) -> dict[str, str]:
    value = {"AMENT_PREFIX_PATH": os.pathsep.join(str(p) for p in prefixes)} if prefixes else {}
    return {**value, **extra}


# --- the ament index -----------------------------------------------------------------------------


def test_first_prefix_listing_a_package_wins(tmp_path: Path) -> None:
    first = installed(tmp_path / "ws1", "shared", "only_first")
    second = installed(tmp_path / "ws2", "shared", "only_second")
    (tmp_path / "ws2" / "share" / "ament_index" / "resource_index" / "packages" / ".hidden").touch()
    index = packages.index(environ=env(first, tmp_path / "missing", second))
    assert index.ament_prefixes() == [str(first), str(second)]
    assert index.get("shared").share_directory == str(first / "share" / "shared")
    assert index.get("only_second").prefix == str(second)
    assert index.installed_packages() == {
        "only_first": str(first),
        "shared": str(first),
        "only_second": str(second),
    }


def test_installed_package_wins_over_a_source_package(tmp_path: Path) -> None:
    prefix = installed(tmp_path / "install", "robot_description")
    src = source(tmp_path / "src" / "robot_description", "robot_description")
    index = packages.index(environ=env(prefix), extra_paths=[str(tmp_path / "src")])
    found = index.get("robot_description")
    assert (found.installed, found.share_directory) == (
        True,
        str(prefix / "share/robot_description"),
    )
    alone = packages.index(environ={}, extra_paths=[str(tmp_path / "src")]).get("robot_description")
    assert (alone.installed, alone.share_directory, alone.prefix) == (False, str(src), str(src))


def test_source_package_name_comes_from_package_xml_not_the_folder(tmp_path: Path) -> None:
    folder = source(tmp_path / "src" / "checkout-of-thing", "thing_description")
    index = packages.index(environ={}, extra_paths=[str(tmp_path / "src")])
    assert index.get("thing_description").share_directory == str(folder)
    assert index.find("checkout-of-thing") is None


def test_explicit_paths_package_folders_and_env_in_order(tmp_path: Path) -> None:
    a = source(tmp_path / "a" / "dup", "dup")
    b = source(tmp_path / "b" / "dup", "dup")
    direct = source(tmp_path / "direct", "direct_pkg")
    search = PackageSearch([str(tmp_path / "a")])
    environ = {"MLAUNCH_PACKAGE_PATH": os.pathsep.join([str(direct), str(tmp_path / "b")])}
    index = packages.index(search=search, environ=environ)
    assert index.get("dup").share_directory == str(a)
    assert index.get("direct_pkg").share_directory == str(direct)
    assert index.source_paths()[:3] == [str(tmp_path / "a"), str(direct), str(tmp_path / "b")]
    only_env = packages.index(environ={"MLAUNCH_PACKAGE_PATH": str(tmp_path / "b")})
    assert only_env.get("dup").share_directory == str(b)


def test_scan_skips_build_trees_hidden_ignored_and_virtualenvs(tmp_path: Path) -> None:
    root = tmp_path / "repo"
    source(root / "src" / "good", "good")
    for skipped in ("build", "install", "log", ".hidden", "node_modules"):
        source(root / skipped / "pkg", f"in_{skipped.strip('.')}")
    source(root / "ignored" / "pkg", "in_ignored")
    (root / "ignored" / "COLCON_IGNORE").touch()
    source(root / "venv" / "pkg", "in_venv")
    (root / "venv" / "pyvenv.cfg").touch()
    source(root / "src" / "good" / "nested", "nested_in_package")  # packages do not nest
    (root / "broken").mkdir()
    (root / "broken" / "package.xml").write_text("<package><name>unclosed")
    found = packages.scan(str(root))
    assert found == {"good": str(root / "src" / "good")}


def test_launch_file_tree_is_searched_up_to_the_repository_root(tmp_path: Path) -> None:
    repo = tmp_path / "repo"
    (repo / ".git").mkdir(parents=True)
    desc = source(repo / "robots" / "bot_description", "bot_description")
    launch = repo / "bringup" / "launch" / "sim.launch.py"
    launch.parent.mkdir(parents=True)
    launch.write_text("")
    assert packages.source_root(str(launch)) == str(repo)
    index = packages.index(environ={}, launch_files=[str(launch)])
    assert index.get("bot_description").share_directory == str(desc)


def test_without_a_marker_the_folder_above_the_launch_files_package(tmp_path: Path) -> None:
    ws = tmp_path / "ws" / "src"
    mine = source(ws / "my_bringup", "my_bringup")
    sibling = source(ws / "my_description", "my_description")
    launch = mine / "launch" / "a.launch.py"
    launch.parent.mkdir()
    launch.write_text("")
    assert packages.source_root(str(launch)) == str(ws)
    index = packages.index(environ={}, launch_files=[str(launch)])
    assert index.get("my_description").share_directory == str(sibling)
    lone = tmp_path / "elsewhere" / "x.launch.py"
    lone.parent.mkdir()
    lone.write_text("")
    assert packages.source_root(str(lone)) is None


def test_missing_package_error_says_where_it_looked(tmp_path: Path) -> None:
    prefix = installed(tmp_path / "install", "other")
    index = packages.index(environ=env(prefix), extra_paths=[str(tmp_path / "src")])
    with pytest.raises(PackageNotFoundError) as err:
        index.get("ghost_pkg")
    message = str(err.value)
    assert message.startswith("package 'ghost_pkg' not found (ament prefixes searched: ")
    assert str(prefix) in message and str(tmp_path / "src") in message
    assert isinstance(err.value, KeyError) and isinstance(err.value, LookupError)
    unset = packages.index(environ={}).searched()
    assert unset.startswith("AMENT_PREFIX_PATH is not set; ")
    assert "--package-path DIR" in unset and "MLAUNCH_PACKAGE_PATH" in unset


def test_scanning_this_repository_finds_its_robots_once() -> None:
    # How fast the scan is belongs to the benchmarks; here: it finds them, and it is cached.
    found = packages.scan(str(REPO))
    assert found["jtbot_description"] == str(REPO / "robots" / "jtbot_description")
    assert found["smartcar_description"] == str(REPO / "robots" / "smartcar_description")
    assert packages.scan(str(REPO)) is found


# --- find_launch_file (mlaunch PKG FILE) ---------------------------------------------------------


def test_find_launch_file_walks_the_share_directory(tmp_path: Path) -> None:
    prefix = installed(tmp_path / "install", "bringup")
    share = prefix / "share" / "bringup"
    (share / "launch" / "deep").mkdir(parents=True)
    (share / "launch" / "deep" / "robot.launch.py").write_text("")
    (share / "launch" / "a.launch.xml").write_text("")
    (share / "config").mkdir()
    (share / "config" / "a.launch.xml").write_text("")
    with searching(PackageSearch(environ=env(prefix))):
        assert packages.find_launch_file("bringup", "robot.launch.py") == str(
            share / "launch" / "deep" / "robot.launch.py"
        )
        with pytest.raises(LaunchFileError, match="'nope.launch.py' was not found in the share"):
            packages.find_launch_file("bringup", "nope.launch.py")
        with pytest.raises(LaunchFileError, match="found more than once") as err:
            packages.find_launch_file("bringup", "a.launch.xml")
        assert str(share / "config" / "a.launch.xml") in str(err.value)
        with pytest.raises(PackageNotFoundError, match="package 'nobody' not found"):
            packages.find_launch_file("nobody", "x.launch.py")


def test_find_launch_file_in_a_source_package(tmp_path: Path) -> None:
    pkg = source(tmp_path / "src" / "demo_bringup", "demo_bringup")
    (pkg / "launch").mkdir()
    (pkg / "launch" / "demo.launch.yaml").write_text("")
    (pkg / "build" / "launch").mkdir(parents=True)
    (pkg / "build" / "launch" / "demo.launch.yaml").write_text("")  # a build tree is not searched
    with searching(PackageSearch([str(tmp_path / "src")], environ={})):
        assert packages.find_launch_file("demo_bringup", "demo.launch.yaml") == str(
            pkg / "launch" / "demo.launch.yaml"
        )


# --- ament_index_python and the substitutions ----------------------------------------------------


def test_ament_index_names_answer_installed_and_source_packages(tmp_path: Path) -> None:
    prefix = installed(tmp_path / "install", "inst")
    src = source(tmp_path / "src" / "srcpkg", "srcpkg")
    with searching(PackageSearch([str(tmp_path / "src")], environ=env(prefix))):
        assert ament_index.get_package_share_directory("inst") == str(prefix / "share" / "inst")
        assert ament_index.get_package_prefix("inst") == str(prefix)
        assert ament_index.get_package_share_directory("srcpkg") == str(src)
        assert ament_index.get_package_share_path("srcpkg") == src
        assert ament_index.get_package_prefix("srcpkg") == str(src)
        with_prefixes = ament_index.get_packages_with_prefixes()
        assert with_prefixes["inst"] == str(prefix) and with_prefixes["srcpkg"] == str(src)
        assert ament_index.get_resource("packages", "inst") == ("", str(prefix))
        assert ament_index.get_resource("packages", "srcpkg") == ("", str(src))
        assert ament_index.has_resource("packages", "missing_one") is False
        assert ament_index.get_search_paths() == [str(prefix)]
        with pytest.raises(ament_index.PackageNotFoundError):
            ament_index.get_package_share_directory("missing_one")
        with pytest.raises(KeyError):
            ament_index.get_package_prefix("missing_one")
        with pytest.raises(ValueError, match="not a valid package name"):
            ament_index.get_package_share_directory("bad/name")
        with pytest.raises(LookupError):
            ament_index.get_resource("messages", "x")


def test_ament_index_search_paths_need_the_variable() -> None:
    with (
        searching(PackageSearch(environ={})),
        pytest.raises(OSError, match="AMENT_PREFIX_PATH' is not set or empty"),
    ):
        ament_index.get_search_paths()


def test_find_package_substitutions_use_the_context(tmp_path: Path) -> None:
    prefix = installed(tmp_path / "install", "inst")
    repo = tmp_path / "repo"
    (repo / "pyproject.toml").parent.mkdir(parents=True)
    (repo / "pyproject.toml").write_text("")
    src = source(repo / "desc", "near_desc")
    launch = repo / "launch" / "x.launch.py"
    ctx = LaunchContext(environment=env(prefix))
    with ctx.file_locals(str(launch)):
        assert perform(ctx, FindPackageShare("near_desc")) == str(src)
        assert perform(ctx, FindPackagePrefix("inst")) == str(prefix)
    with pytest.raises(PackageNotFoundError, match="package 'near_desc' not found"):
        perform(ctx, FindPackageShare("near_desc"))  # outside the launch file: not near it


def test_a_launch_file_finds_a_package_next_to_it_while_loading(tmp_path: Path) -> None:
    """The seed's pattern: share directories looked up in launch-file code, before resolving."""
    repo = tmp_path / "repo"
    repo.mkdir()
    (repo / ".git").mkdir()
    desc = source(repo / "robots" / "seed_description", "seed_description")
    launch = repo / "launch" / "seed.launch.py"
    launch.parent.mkdir()
    launch.write_text(
        textwrap.dedent(
            """\
            import os
            from ament_index_python.packages import get_package_share_directory
            from launch import LaunchDescription
            from launch.actions import LogInfo
            from launch_ros.substitutions import FindPackageShare

            def generate_launch_description():
                share = get_package_share_directory('seed_description')
                found = FindPackageShare(package='seed_description').find('seed_description')
                return LaunchDescription([LogInfo(msg=share), LogInfo(msg=found)])
            """
        )
    )
    description = readers.load(str(launch))
    plan = resolve(
        description, path=str(launch), arguments={}, environ={}, options=ResolveOptions()
    )
    assert [s.message for s in plan.steps if isinstance(s, Log)] == [str(desc), str(desc)]


def test_the_runs_search_is_an_explicit_input(tmp_path: Path) -> None:
    """The search the pipeline runs with: active for ament_index calls, given to resolve."""
    repo = tmp_path / "repo"
    (repo / ".git").mkdir(parents=True)
    desc = source(repo / "pkgs" / "conf_desc", "conf_desc")
    search = PackageSearch(launch_file=str(repo / "a.launch.py"), environ={})
    with searching(search):
        assert ament_index.get_package_share_directory("conf_desc") == str(desc)
    with pytest.raises(PackageNotFoundError):
        ament_index.get_package_share_directory("conf_desc")  # no longer active
    ld = LaunchDescription([LogInfo(msg=FindPackageShare("conf_desc"))])
    plan = resolve(ld, path=None, arguments={}, environ={}, options=ResolveOptions(packages=search))
    assert [s.message for s in plan.steps if isinstance(s, Log)] == [str(desc)]
    with pytest.raises(PackageNotFoundError):
        resolve(ld, path=None, arguments={}, environ={}, options=ResolveOptions())


def test_symlinked_packages_are_found_and_loops_do_not_hang(tmp_path: Path) -> None:
    elsewhere = source(tmp_path / "elsewhere" / "linked_pkg", "linked_pkg")
    src = tmp_path / "ws" / "src"
    src.mkdir(parents=True)
    (src / "linked_pkg").symlink_to(elsewhere)
    (src / "loop").mkdir()
    (src / "loop" / "back").symlink_to(src)
    found = packages.scan(str(src))
    assert found == {"linked_pkg": str(src / "linked_pkg")}
