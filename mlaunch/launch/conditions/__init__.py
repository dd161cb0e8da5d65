"""``launch.conditions``: whether an action is visited, decided while resolving.

Each condition lives in its own module, named as upstream's; the base class is
``launch.condition``. This package only gathers the names (``mlaunch.launch.gathering``).
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.condition import Condition
    from mlaunch.launch.conditions.evaluate_condition_expression_impl import (
        evaluate_condition_expression,
    )
    from mlaunch.launch.conditions.if_condition import IfCondition
    from mlaunch.launch.conditions.invalid_condition_expression_error import (
        InvalidConditionExpressionError,
    )
    from mlaunch.launch.conditions.launch_configuration_equals import LaunchConfigurationEquals
    from mlaunch.launch.conditions.launch_configuration_not_equals import (
        LaunchConfigurationNotEquals,
    )
    from mlaunch.launch.conditions.unless_condition import UnlessCondition

_gathered = Gathered(
    globals(),
    {
        "Condition": "mlaunch.launch.condition",
        "IfCondition": ".if_condition",
        "InvalidConditionExpressionError": ".invalid_condition_expression_error",
        "LaunchConfigurationEquals": ".launch_configuration_equals",
        "LaunchConfigurationNotEquals": ".launch_configuration_not_equals",
        "UnlessCondition": ".unless_condition",
        "evaluate_condition_expression": ".evaluate_condition_expression_impl",
    },
    submodules=(
        "evaluate_condition_expression_impl",
        "if_condition",
        "invalid_condition_expression_error",
        "launch_configuration_equals",
        "launch_configuration_not_equals",
        "unless_condition",
    ),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = [
    "Condition",
    "IfCondition",
    "InvalidConditionExpressionError",
    "LaunchConfigurationEquals",
    "LaunchConfigurationNotEquals",
    "UnlessCondition",
    "evaluate_condition_expression",
]
