"""``launch.frontend.Entity``: one tag of a markup launch file, as parse methods read it.

The XML and YAML implementations (``launch_xml.Entity``, ``launch_yaml.Entity``) live with the
readers; third-party ``parse(entity, parser)`` methods see only this interface.
"""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from typing import Any


class Entity:
    """Single item in the intermediate frontend representation (abstract)."""

    @property
    def type_name(self) -> str:
        """The tag (XML element name, YAML key)."""
        raise NotImplementedError()

    @property
    def parent(self) -> Entity | None:
        """The enclosing entity, None at the root or when not known."""
        raise NotImplementedError()

    @property
    def children(self) -> list[Entity]:
        """The nested entities (reading them counts them as parsed)."""
        raise NotImplementedError()

    def get_attr(
        self,
        name: str,
        *,
        data_type: Any = str,
        optional: bool = False,
        can_be_str: bool = True,
    ) -> Any:
        """The attribute ``name`` as ``data_type`` (str, int, float, bool, List[...], None for
        YAML rules, List[Entity] for sub-entities); None when ``optional`` and absent.

        Raises AttributeError when it is missing, TypeError or ValueError when it has the wrong
        type (XML coerces text, YAML checks the value).
        """
        raise NotImplementedError()

    def assert_entity_completely_parsed(self) -> None:
        """Raise when an attribute or a nested entity was not read (called after ``parse``)."""
        raise NotImplementedError()


__all__ = ["Entity"]
