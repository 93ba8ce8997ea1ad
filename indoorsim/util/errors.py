"""The one error for a name that is not in a registry, with the names that are.

Every registry of the package (scenarios, routes, carrying modes, devices, ...)
raises a subclass of :class:`UnknownNameError` for a name it does not know, so
a caller can catch one type, read the valid names off ``.valid``, and print
the same kind of message everywhere::

    unknown device 'nokia_3310'; valid devices are: honor_50, ideal, ...

Beside it, :class:`IndoorsimWarning`: the base of the warnings meant for the
user, which the command line prints as one line.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import ClassVar

__all__ = ["IndoorsimWarning", "UnknownNameError"]


class IndoorsimWarning(UserWarning):
    """A warning meant for the user, such as rows a reader skipped.

    The command line prints it as one line, ``indoorsim: warning: <message>``.
    """


class UnknownNameError(LookupError):
    """A name looked up in a registry that does not hold it.

    Subclasses name what is looked up in :attr:`kind` (and the valid names'
    label in :attr:`valid_label`, when "valid <kind>s" does not read well).
    Where a lookup used to raise ``KeyError`` or ``ValueError``, its subclass
    derives from that too, so existing ``except`` clauses keep working.

    Args:
        name: the name that was looked up.
        valid: the names that exist, in the order to list them.
        where: what the registry belongs to, e.g. ``"in scenario 'minimal_room'"``.
        kind: what is looked up, for a registry without a subclass of its own
            (default: the class's :attr:`kind`).

    Attributes:
        name: the name that was looked up.
        valid: the names that exist.
        where: the registry's owner, or ``""``.
        kind: what is looked up, singular: ``"device"``, ``"carrying mode"``.
    """

    kind: str = "name"
    valid_label: ClassVar[str] = ""
    """How the message introduces the valid names (default ``"valid <kind>s"``)."""

    def __init__(self, name: str, valid: Iterable[str], where: str = "", kind: str = ""):
        self.name = name
        self.valid = tuple(valid)
        self.where = where
        self.kind = kind or type(self).kind
        super().__init__(self.message)

    @property
    def message(self) -> str:
        """``unknown <kind> '<name>' [<where>]; valid <kind>s are: a, b, c``."""
        where = f" {self.where}" if self.where else ""
        label = self.valid_label or f"valid {self.kind}s"
        return (
            f"unknown {self.kind} {self.name!r}{where}; "
            f"{label} are: {', '.join(self.valid) or 'none'}"
        )

    def __str__(self) -> str:
        # KeyError.__str__ would repr() the message, quoting it.
        return self.message

    def __reduce__(self) -> tuple[type[UnknownNameError], tuple[str, tuple[str, ...], str, str]]:
        # Rebuilt from its fields, not from ``args``: a Dask worker's error reaches the client.
        return type(self), (self.name, self.valid, self.where, self.kind)
