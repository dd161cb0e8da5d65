"""``launch_ros.utilities``: namespaces, parameters, remap rules and node-name counts."""

from mlaunch.launch_ros.utilities.evaluate_parameters import (
    evaluate_parameter_dict,
    evaluate_parameters,
)
from mlaunch.launch_ros.utilities.namespace_utils import (
    is_namespace_absolute,
    is_root_namespace,
    make_namespace_absolute,
    prefix_namespace,
)
from mlaunch.launch_ros.utilities.normalize_parameters import (
    normalize_parameter_dict,
    normalize_parameters,
)
from mlaunch.launch_ros.utilities.normalize_remap_rule import (
    normalize_remap_rule,
    normalize_remap_rules,
)
from mlaunch.launch_ros.utilities.track_node_names import add_node_name, get_node_name_count

# launch_ros spells the dict evaluator both ways.
evaluate_parameters_dict = evaluate_parameter_dict
normalize_parameters_dict = normalize_parameter_dict

__all__ = [
    "add_node_name",
    "evaluate_parameter_dict",
    "evaluate_parameters",
    "evaluate_parameters_dict",
    "get_node_name_count",
    "is_namespace_absolute",
    "is_root_namespace",
    "make_namespace_absolute",
    "normalize_parameter_dict",
    "normalize_parameters",
    "normalize_parameters_dict",
    "normalize_remap_rule",
    "normalize_remap_rules",
    "prefix_namespace",
]
