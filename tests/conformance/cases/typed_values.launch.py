from launch import LaunchDescription
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue


def generate_launch_description():
    return LaunchDescription(
        [
            Node(
                package="conf_pkg",
                executable="recorder",
                name="typed",
                parameters=[
                    {
                        "text_float": "1.0",
                        "text_true": "true",
                        "text_octal": "007",
                        "text_empty": "",
                        "real_float": 1.0,
                        "as_str": ParameterValue("1.0", value_type=str),
                        "as_yaml": ParameterValue("[1, 2]"),
                        "nested": {"a": {"b": "2"}},
                    }
                ],
            ),
        ]
    )
