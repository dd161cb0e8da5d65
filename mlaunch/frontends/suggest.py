""" "Did you mean" hints over the declared launch arguments, bounded in time and in length.

A close-match search compares the unknown name with every declared one; done for each of many
unknown names against many declared ones it was quadratic (2,000 against 51,000 took two
minutes), and the fallback listed every declared name. Both are capped here.
"""

from __future__ import annotations

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from collections.abc import Iterable

# Name comparisons one Suggester makes in all (1-7 µs each): past it, hints are left out.
COMPARISON_BUDGET = 50_000
# Declared names a hint lists when nothing is close.
LISTED = 20


class Suggester:
    """Hints for names that are not among ``declared``, sharing one comparison budget."""

    def __init__(self, declared: Iterable[str], budget: int = COMPARISON_BUDGET) -> None:
        self.names = list(declared)
        self.budget = budget
        self._listing: str | None = None

    def hint(self, name: str) -> str:
        """`` (did you mean 'x'?)``, else ``; declared: a, b ...`` (capped), else empty."""
        if not self.names:
            return ""
        if self.budget >= len(self.names):
            import difflib  # only when a name is unknown: ~1 ms of start-up otherwise

            self.budget -= len(self.names)
            close = difflib.get_close_matches(name, self.names, n=1)
            if close:
                return f" (did you mean {close[0]!r}?)"
        return f"; declared: {self.listing()}"

    def listing(self) -> str:
        if self._listing is None:
            shown = sorted(self.names)[:LISTED]
            more = len(self.names) - len(shown)
            tail = f" and {more} more (--show-args lists them)" if more else ""
            self._listing = ", ".join(shown) + tail
        return self._listing
