"""The ``$(name arg ...)`` language of YAML and XML launch files: a hand-written scanner.

``parse_template(text)`` turns an attribute value into a list of parts (``str`` and
Substitution objects, the same classes the Python API builds), once, when the file loads. The
grammar is ROS 2's (``launch/frontend/grammar.lark``):

- text mixed with ``$(IDENTIFIER)`` or ``$(IDENTIFIER arg arg ...)``; arguments are separated by
  single spaces and each one concatenates text and nested ``$(...)``;
- an argument quoted with ``'...'`` or ``"..."`` may hold spaces and parentheses; inside it, the
  arguments of a nested ``$(...)`` cannot be quoted again (ROS 2's rule), the other quote
  character is plain text there;
- a backslash escapes the character after it, as launch's ``replace_escaped_characters`` does
  (``$ ( ) ' "``, itself, and any other: ``\\d`` is ``d``), except a line break, and in an
  unquoted argument a blank, which end the text it is in (the backslash is kept); a ``$`` not
  followed by ``(`` is plain text, and so are quotes and parentheses outside ``$(...)``.

Deliberate difference from ROS 2: a lone ``$`` is text (ROS 2's grammar rejects it).

Errors are ``TemplateError(message, index)``; the frontend turns the index into file:line:col.

The names: launch's own (``SUBSTITUTIONS``), those a caller adds (``parse_template(text,
table)``: launch_ros's, ``mlaunch.launch_ros.subst``, which the readers use), then those a
package exposed (``launch.frontend.expose_substitution``).
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable
from functools import partial

import mlaunch.launch.substitutions as core
from mlaunch.launch.substitution import SUBSTITUTION_DEPTH_LIMIT, Substitution

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any

Part = str | Substitution
Parts = list[Part]

_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")
# Runs of characters that are plain text in each context (the scanner jumps over them).
_TOP_SPECIAL = re.compile(r"[\\$]")
_UNQUOTED_PLAIN = re.compile(r"[^ ()\\$'\"]+")
_QUOTED_PLAIN = {q: re.compile(rf"[^{q}\\$]+") for q in "'\""}


class TemplateError(ValueError):
    """A malformed ``$(...)`` template; ``index`` is where in the text the problem is."""

    def __init__(self, message: str, index: int, unknown: str | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.index = index
        self.unknown = unknown  # the name of an unknown substitution, when that is the problem


# --- the substitution table --------------------------------------------------------------------


class SubstitutionSpec:
    """One ``$(name ...)``: how many arguments it takes and how to build it from them.

    A plain class: dataclasses costs ~8 ms to import on every YAML/XML launch.
    """

    __slots__ = ("build", "max_args", "min_args", "usage")

    def __init__(
        self,
        usage: str,
        min_args: int,
        max_args: int | None,
        build: Callable[[list[Any]], Substitution],
    ) -> None:
        self.usage = usage
        self.min_args = min_args
        self.max_args = max_args
        self.build = build


def _modules_value(value: Any) -> Any:
    """PythonExpression's module list: one text, split on commas when performed."""
    if isinstance(value, (str, Substitution)):
        return value
    return _Joined(value)


class _Joined(Substitution):
    """Several parts performed and concatenated into one value (for a list-taking keyword)."""

    def __init__(self, parts: list[Part]) -> None:
        self.parts = core.normalize(parts)

    def perform(self, context: Any) -> str:
        return core.perform_substitutions(context, self.parts)

    def describe(self) -> str:
        return " + ".join(p.describe() for p in self.parts)


def _var(a: list[Any]) -> Substitution:
    return core.LaunchConfiguration(a[0], default=a[1] if len(a) > 1 else None)


def _env(a: list[Any]) -> Substitution:
    return core.EnvironmentVariable(a[0], default_value=a[1] if len(a) > 1 else None)


def _eval(a: list[Any]) -> Substitution:
    if len(a) > 1:
        return core.PythonExpression(a[0], python_modules=_modules_value(a[1]))
    return core.PythonExpression(a[0])


def _command(a: list[Any]) -> Substitution:
    if len(a) > 1:
        if isinstance(a[1], str) and a[1] not in core.Command.ON_STDERR:
            raise ValueError(
                f"command's on_stderr is {a[1]!r}; valid: {', '.join(core.Command.ON_STDERR)}"
            )
        return core.Command(a[0], on_stderr=a[1])
    return core.Command(a[0])


def _for_var(a: list[Any]) -> Substitution:
    return core.ForEachVar(a[0], default_value=a[1] if len(a) > 1 else None)


def _if(a: list[Any]) -> Substitution:
    return core.IfElseSubstitution(a[0], a[1], a[2] if len(a) > 2 else "")


SUBSTITUTIONS: dict[str, SubstitutionSpec] = {
    "var": SubstitutionSpec("$(var name [default])", 1, 2, _var),
    "env": SubstitutionSpec("$(env NAME [default])", 1, 2, _env),
    "eval": SubstitutionSpec("$(eval 'expression' [modules])", 1, 2, _eval),
    "command": SubstitutionSpec("$(command 'cmd args' [fail|warn|ignore|capture])", 1, 2, _command),
    "find-exec": SubstitutionSpec(
        "$(find-exec name)", 1, 1, lambda a: core.FindExecutable(name=a[0])
    ),
    "anon": SubstitutionSpec("$(anon name)", 1, 1, lambda a: core.AnonName(a[0])),
    "dirname": SubstitutionSpec("$(dirname)", 0, 0, lambda a: core.ThisLaunchFileDir()),
    "filename": SubstitutionSpec("$(filename)", 0, 0, lambda a: core.ThisLaunchFile()),
    "log_dir": SubstitutionSpec("$(log_dir)", 0, 0, lambda a: core.LaunchLogDir()),
    "launch_log_dir": SubstitutionSpec("$(launch_log_dir)", 0, 0, lambda a: core.LaunchLogDir()),
    "file-content": SubstitutionSpec(
        "$(file-content path)", 1, 1, lambda a: core.FileContent(a[0])
    ),
    "not": SubstitutionSpec("$(not value)", 1, 1, lambda a: core.NotSubstitution(a[0])),
    "and": SubstitutionSpec("$(and a b)", 2, 2, lambda a: core.AndSubstitution(a[0], a[1])),
    "or": SubstitutionSpec("$(or a b)", 2, 2, lambda a: core.OrSubstitution(a[0], a[1])),
    "any": SubstitutionSpec("$(any a b ...)", 1, None, lambda a: core.AnySubstitution(*a)),
    "all": SubstitutionSpec("$(all a b ...)", 1, None, lambda a: core.AllSubstitution(*a)),
    "equals": SubstitutionSpec(
        "$(equals a b)", 2, 2, lambda a: core.EqualsSubstitution(a[0], a[1])
    ),
    "not-equals": SubstitutionSpec(
        "$(not-equals a b)", 2, 2, lambda a: core.NotEqualsSubstitution(a[0], a[1])
    ),
    "if": SubstitutionSpec("$(if condition value [else-value])", 2, 3, _if),
    # Newer than Jazzy (--check says so): launch 3.8 (Kilted), string-join 3.9.5 (Rolling).
    "for-var": SubstitutionSpec("$(for-var name [default])", 1, 2, _for_var),
    "index": SubstitutionSpec("$(index name)", 1, 1, lambda a: core.ForLoopIndex(a[0])),
    "string-join": SubstitutionSpec(
        "$(string-join delimiter a [b ...])",
        2,
        None,
        lambda a: core.StringJoinSubstitution(a[1:], delimiter=a[0]),
    ),
}


Table = dict[str, SubstitutionSpec]


def spec_for(name: str, table: Table | None = None) -> SubstitutionSpec | None:
    """``$(name)``: from ``table``, launch's own, else one a package exposed."""
    spec = (table or SUBSTITUTIONS).get(name) or SUBSTITUTIONS.get(name)
    if spec is not None:
        return spec
    from mlaunch.launch.frontend.expose import substitution_parse_methods

    if name not in substitution_parse_methods:
        return None
    return SubstitutionSpec(f"$({name} ...)", 0, None, partial(_exposed, name))


def _exposed(name: str, args: list[Any]) -> Substitution:
    """``$(name ...)`` built by the parse method a package exposed: each argument a list of
    substitutions, as upstream hands them over."""
    from mlaunch.launch.frontend.expose import instantiate_substitution

    try:
        return instantiate_substitution(name, [list(core.normalize(a)) for a in args])
    except (AttributeError, LookupError, RuntimeError, TypeError, ValueError) as e:
        raise ValueError(f"{type(e).__name__}: {e}") from e


def _unknown_name(name: str, table: Table | None) -> str:
    from mlaunch.launch.frontend.expose import substitution_parse_methods

    known = sorted({*SUBSTITUTIONS, *(table or ()), *substitution_parse_methods})
    close = difflib.get_close_matches(name, known, n=1, cutoff=0.6)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return f"unknown substitution {name!r}{hint}; valid: {', '.join(known)}"


# --- the scanner ---------------------------------------------------------------------------------


def has_substitutions(text: str) -> bool:
    """Whether the text needs the scanner at all (anything else is taken as it is)."""
    return "$(" in text or "\\" in text


def parse_template(text: str, table: Table | None = None) -> Parts:
    """The parts of an attribute value: plain text and substitutions, adjacent text merged
    (``table``: names beyond launch's own)."""
    if not has_substitutions(text):
        return [text]
    parts: Parts = []
    _Scanner(text, table).top(parts)
    return parts


class _Scanner:
    """Recursive descent over one attribute value."""

    def __init__(self, text: str, table: Table | None = None) -> None:
        self.s = text
        self.n = len(text)
        self.table = table
        self.depth = 0  # substitutions open around the one being read

    def top(self, parts: Parts) -> None:
        s, i, n = self.s, 0, self.n
        buf: list[str] = []
        while i < n:
            m = _TOP_SPECIAL.search(s, i)
            if m is None:
                buf.append(s[i:])
                break
            j = m.start()
            if j > i:
                buf.append(s[i:j])
            if s[j] == "\\":
                # launch drops a backslash before any character but a line break
                if j + 1 < n and s[j + 1] != "\n":
                    buf.append(s[j + 1])
                    i = j + 2
                else:
                    buf.append("\\")
                    i = j + 1
            elif j + 1 < n and s[j + 1] == "(":
                _flush(buf, parts)
                sub, i = self.substitution(j, None)
                parts.append(sub)
            else:
                buf.append("$")
                i = j + 1
        _flush(buf, parts)
        if not parts:
            parts.append("")

    def substitution(self, start: int, quote: str | None) -> tuple[Substitution, int]:
        """``$(name args)`` at ``start``; ``quote`` is the quote the whole thing sits in."""
        s = self.s
        m = _IDENTIFIER.match(s, start + 2)
        if m is None:
            raise TemplateError(
                "expected a substitution name after '$(' (a letter, then letters, digits, _ or -)",
                start + 2,
            )
        name = m.group()
        spec = spec_for(name, self.table)
        if spec is None:
            raise TemplateError(_unknown_name(name, self.table), m.start(), unknown=name)
        if self.depth >= SUBSTITUTION_DEPTH_LIMIT:
            raise TemplateError(
                f"substitutions nest deeper than {SUBSTITUTION_DEPTH_LIMIT} levels, mlaunch's"
                " limit; flatten them",
                start,
            )
        self.depth += 1
        try:
            return self.substitution_body(start, name, spec, m.end(), quote)
        finally:
            self.depth -= 1

    def substitution_body(
        self, start: int, name: str, spec: SubstitutionSpec, i: int, quote: str | None
    ) -> tuple[Substitution, int]:
        """The arguments and ')' of ``$(name`` (read up to ``i``), built into its Substitution."""
        s = self.s
        args: list[Parts] = []
        if i >= self.n:
            raise TemplateError(f"'$({name}' is not closed with ')'", start)
        if s[i] == " ":
            i = self.arguments(i + 1, name, start, quote, args)
        elif s[i] != ")":
            raise TemplateError(
                f"expected ' ' or ')' after the substitution name {name!r}, got {s[i]!r}", i
            )
        count = len(args)
        if count < spec.min_args or (spec.max_args is not None and count > spec.max_args):
            raise TemplateError(
                f"$({name}) takes {_arity(spec)}, got {count}; usage: {spec.usage}", start
            )
        try:
            sub = spec.build([_value(a) for a in args])
        except (ValueError, TypeError) as e:
            raise TemplateError(f"$({name}): {e}", start)
        return sub, i + 1

    def arguments(self, i: int, name: str, start: int, quote: str | None, args: list[Parts]) -> int:
        """Arguments from ``i`` up to the closing ')' of ``$(name``; returns its index."""
        s, n = self.s, self.n
        while True:
            if i >= n:
                raise TemplateError(f"'$({name}' is not closed with ')'", start)
            c = s[i]
            if c == " " or c == ")":
                raise TemplateError(
                    f"empty argument in '$({name} ...)': arguments are separated by single"
                    " spaces (quote an empty or spaced value: '')",
                    i,
                )
            value: Parts = []
            if quote is None and c in "'\"":
                i = self.quoted(i, value)
                if i < n and s[i] not in " )":
                    raise TemplateError(
                        f"text right after a quoted argument of '$({name} ...)';"
                        " put the whole argument inside the quotes",
                        i,
                    )
            else:
                i = self.unquoted(i, name, start, quote, value)
            args.append(value)
            if i >= n:
                raise TemplateError(f"'$({name}' is not closed with ')'", start)
            if s[i] == ")":
                return i
            i += 1  # the single space before the next argument

    def unquoted(self, i: int, name: str, start: int, quote: str | None, value: Parts) -> int:
        s, n = self.s, self.n
        buf: list[str] = []
        plain = _UNQUOTED_PLAIN.match
        while i < n:
            m = plain(s, i)
            if m is not None:
                buf.append(m.group())
                i = m.end()
                if i >= n:
                    break
            c = s[i]
            if c == " " or c == ")":
                break
            after = self.escape_or_nested(i, buf, value, quote, blank_ends=True)
            if after is not None:
                i = after
            elif c == "(":
                raise TemplateError(
                    f"unescaped '(' in an argument of '$({name} ...)'; write \\( or quote"
                    " the argument",
                    i,
                )
            elif c in "'\"" and (quote is None or c == quote):
                if quote is not None:
                    raise TemplateError(
                        f"'$({name}' is not closed with ')' before the closing quote {c}", start
                    )
                raise TemplateError(
                    f"quote {c} in the middle of an argument of '$({name} ...)';"
                    f" quote the whole argument or escape it as \\{c}",
                    i,
                )
            else:
                buf.append(c)
                i += 1
        _flush(buf, value)
        return i

    def escape_or_nested(
        self, i: int, buf: list[str], value: Parts, quote: str | None, *, blank_ends: bool
    ) -> int | None:
        """A backslash escape or a nested ``$(`` at ``i``: consume it, return the next index.

        None when ``s[i]`` is neither, so the caller handles that character itself.
        """
        s, n = self.s, self.n
        c = s[i]
        if c == "\\":
            # a line break, or a blank in an unquoted argument, ends the text the backslash is
            # in: it is kept there, as launch's grammar reads it
            nxt = s[i + 1] if i + 1 < n else "\n"
            if nxt != "\n" and not (blank_ends and nxt == " "):
                buf.append(s[i + 1])
                return i + 2
            buf.append("\\")
            return i + 1
        if c == "$" and i + 1 < n and s[i + 1] == "(":
            _flush(buf, value)
            sub, i = self.substitution(i, quote)
            value.append(sub)
            return i
        return None

    def quoted(self, i: int, value: Parts) -> int:
        """A '...' or "..." argument starting at the quote ``i``; returns the index after it."""
        s, n = self.s, self.n
        q = s[i]
        open_at = i
        i += 1
        buf: list[str] = []
        plain = _QUOTED_PLAIN[q].match
        while i < n:
            m = plain(s, i)
            if m is not None:
                buf.append(m.group())
                i = m.end()
                if i >= n:
                    break
            c = s[i]
            if c == q:
                _flush(buf, value)
                if not value:
                    value.append("")
                return i + 1
            after = self.escape_or_nested(i, buf, value, q, blank_ends=False)
            if after is not None:
                i = after
            else:
                buf.append(c)
                i += 1
        raise TemplateError(f"the quote {q} opened here is not closed", open_at)


def _flush(buf: list[str], parts: Parts) -> None:
    if not buf:
        return
    text = "".join(buf)
    buf.clear()
    if parts and isinstance(parts[-1], str):
        parts[-1] += text
    else:
        parts.append(text)


def _value(parts: Parts) -> Any:
    """One argument as a constructor takes it: plain text, one substitution, or a list."""
    if len(parts) == 1:
        return parts[0]
    return list(parts)


def _arity(spec: SubstitutionSpec) -> str:
    if spec.max_args is None:
        return f"at least {spec.min_args} argument{'s' if spec.min_args != 1 else ''}"
    if spec.min_args == spec.max_args:
        n = spec.min_args
        return "no arguments" if n == 0 else f"{n} argument{'s' if n != 1 else ''}"
    return f"{spec.min_args} to {spec.max_args} arguments"
