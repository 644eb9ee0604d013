"""One rule for reading a scalar from plain data: a YAML file, a request given as a dict.

The configuration loader (config.py) and the requests (requests.py: services, goals, replay,
the Python client's commands) read numbers, integers, true/false and strings with the same
readers; each path keeps its own error (ConfigError naming the key; Refused, answered
MPIMessagePARAM_INVALID) through the ``fail`` it gives :func:`readers`.

The rule (docs/decisions.md, "One reader for plain data"):

- a number is any real number but a boolean, or a string that spells one (PyYAML reads
  ``1e9``, without an exponent sign, as a string); it is read as a float. Its range, NaN
  included, is the caller's business;
- an integer is an integer, never a boolean, never a float (3.0 is refused, as a ROS int32
  field refuses it);
- true or false is a boolean, never 0 or 1 (as a ROS bool field);
- a string is a string.
"""

from __future__ import annotations

import numbers as _numbers
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

# fail(what, expected, value): the error to raise for ``value`` at ``what``, where ``expected``
# says what was wanted ("a number", "an integer", "true or false", "a string")
Fail = Callable[[str, str, Any], Exception]
Reader = Callable[[Any, str], Any]


@dataclass(frozen=True, slots=True)
class Readers:
    """The four scalar readers of one path, each ``read(value, what)``."""

    number: Callable[[Any, str], float]
    integer: Callable[[Any, str], int]
    boolean: Callable[[Any, str], bool]
    text: Callable[[Any, str], str]

    def of(self, kind: type) -> Reader | None:
        """The reader of values of Python type ``kind`` (exactly: an enum's is None)."""
        return {float: self.number, int: self.integer, bool: self.boolean, str: self.text}.get(kind)


def readers(fail: Fail) -> Readers:
    """The readers that raise ``fail(what, expected, value)`` for a value they cannot read."""

    def number(value: Any, what: str) -> float:
        if type(value) is float:  # what nearly every request holds
            return value
        if isinstance(value, bool) or not isinstance(value, (_numbers.Real, str)):
            raise fail(what, "a number", value)
        try:
            return float(value)
        except (TypeError, ValueError, OverflowError):  # a word; an integer beyond every double
            raise fail(what, "a number", value) from None

    def integer(value: Any, what: str) -> int:
        if type(value) is int:  # (bool is not int's type)
            return value
        if isinstance(value, bool) or not isinstance(value, _numbers.Integral):
            raise fail(what, "an integer", value)
        return int(value)  # numpy's integers

    def boolean(value: Any, what: str) -> bool:
        if value is True or value is False:
            return value
        raise fail(what, "true or false", value)

    def text(value: Any, what: str) -> str:
        if not isinstance(value, str):
            raise fail(what, "a string", value)
        return value

    return Readers(number, integer, boolean, text)
