# Included by nav2_like.launch.py (navigation_launch.py's composed branch, cut down).
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import LoadComposableNodes, SetParameter
from launch_ros.descriptions import ComposableNode, ParameterFile


def generate_launch_description():
    namespace = LaunchConfiguration("namespace")
    container_name = LaunchConfiguration("container_name")
    container_name_full = (namespace, "/", container_name)
    use_sim_time = LaunchConfiguration("use_sim_time")
    autostart = LaunchConfiguration("autostart")
    params_file = LaunchConfiguration("params_file")
    remappings = [("/tf", "tf"), ("/tf_static", "tf_static")]
    lifecycle_nodes = ["controller_server", "smoother_server"]
    return LaunchDescription(
        [
            DeclareLaunchArgument("autostart", default_value="true"),
            DeclareLaunchArgument("use_sim_time", default_value="false"),
            GroupAction(
                condition=IfCondition(LaunchConfiguration("use_composition")),
                actions=[
                    SetParameter("use_sim_time", use_sim_time),
                    LoadComposableNodes(
                        target_container=container_name_full,
                        composable_node_descriptions=[
                            ComposableNode(
                                package="nav2_controller",
                                plugin="nav2_controller::ControllerServer",
                                name="controller_server",
                                parameters=[ParameterFile(params_file, allow_substs=True)],
                                remappings=[*remappings, ("cmd_vel", "cmd_vel_nav")],
                            ),
                            ComposableNode(
                                package="nav2_smoother",
                                plugin="nav2_smoother::SmootherServer",
                                name="smoother_server",
                                parameters=[params_file],
                                remappings=remappings,
                            ),
                            ComposableNode(
                                package="nav2_lifecycle_manager",
                                plugin="nav2_lifecycle_manager::LifecycleManager",
                                name="lifecycle_manager_navigation",
                                parameters=[
                                    {"autostart": autostart, "node_names": lifecycle_nodes}
                                ],
                            ),
                        ],
                    ),
                ],
            ),
        ]
    )
