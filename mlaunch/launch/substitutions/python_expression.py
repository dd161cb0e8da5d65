"""``launch.substitutions.python_expression``, where upstream defines it."""

from mlaunch.launch.substitutions import PythonExpression

__all__ = ["PythonExpression"]
