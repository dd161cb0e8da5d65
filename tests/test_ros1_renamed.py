"""Names of older ROS 1 releases in a native run's resolution: ``$(find xacro)/xacro.py`` (the
seed's) runs the installed xacro, with a warning naming what runs instead."""

from __future__ import annotations

import shutil
from pathlib import Path

from ros1tree import package_tree

from mlaunch.ros1.config import load

REPO = Path(__file__).resolve().parent.parent
MODEL = "'$(find smartcar_description)/urdf/smartcar.urdf.xacro'"


def resolve(tmp_path: Path, program: str, env: dict[str, str]) -> tuple[object, list[str]]:
    launch = tmp_path / f"{program}.launch"
    launch.write_text(
        f'<launch>\n  <param name="robot_description" command="$(find xacro)/{program} {MODEL}"/>'
        "\n</launch>\n"
    )
    config = load(str(launch), {}, environ=env)
    return config.params["/robot_description"], config.warnings


def test_xacro_py_runs_the_installed_xacro_with_a_warning(tmp_path: Path) -> None:
    env = package_tree(tmp_path, extra=(REPO / "robots" / "smartcar_description",))
    new, new_warnings = resolve(tmp_path, "xacro", env)
    old, old_warnings = resolve(tmp_path, "xacro.py", env)
    assert old == new and "<robot" in str(new)
    assert new_warnings == []
    installed = tmp_path / "src" / "xacro" / "xacro"  # the tree's ROS 1 xacro package
    assert old_warnings == [
        f"{tmp_path}/xacro.py.launch:2: {installed}.py is xacro's name in ROS 1 releases"
        f" before Melodic: running {installed}, which replaced it"
    ]


def test_xacro_py_without_a_ros1_xacro_runs_the_pypi_xacro(tmp_path: Path) -> None:
    env = package_tree(tmp_path, extra=(REPO / "robots" / "smartcar_description",))
    shutil.rmtree(tmp_path / "src" / "xacro")  # no ROS 1 xacro package: $(find xacro) is PyPI's
    (tmp_path / "ament" / "share" / "xacro").unlink()
    (
        tmp_path / "ament" / "share" / "ament_index" / "resource_index" / "packages" / "xacro"
    ).unlink()
    old, warnings = resolve(tmp_path, "xacro.py", env)
    assert "<robot" in str(old)
    assert len(warnings) == 1 and warnings[0].startswith(f"{tmp_path}/xacro.py.launch:2: ")
    assert warnings[0].endswith(
        "/xacro.py is xacro's name in ROS 1 releases before Melodic: running xacro (the PyPI"
        " xacro, inside mlaunch), which replaced it"
    )
