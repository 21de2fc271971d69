"""The one error type for bad user input, shared by every layer.

The CLI turns an :class:`~softhand.reduced.vocabulary.errors.InputError` into one line on stderr and exit code 2. The line is
bounded in length: a huge value (a 50 MB list, a long string) is cut to its start.
"""
from __future__ import annotations

#: longest field name and value text in a message [characters]
MAX_FIELD, MAX_VALUE = 120, 120


def short(text: str, limit: int) -> str:
    """``text`` on one line, cut to ``limit`` characters (with '...' and the length)."""
    text = " ".join(str(text).split())
    if len(text) <= limit:
        return text
    return f"{text[:limit]}... ({len(text)} characters)"


class InputError(ValueError):
    """Bad user input: names the field, the value given and what is allowed."""

    def __init__(self, field: str, value, allowed: str):
        if getattr(value, "ndim", None) == 0 and hasattr(value, "item"):
            value = value.item()  # a numpy scalar shown as the number, not np.float64(7.0)
        self.field = field
        self.value = value
        self.allowed = allowed
        shown = short(repr(value), MAX_VALUE)
        super().__init__(f"{short(field, MAX_FIELD)} = {shown}: {short(allowed, 600)}")

    def renamed(self, field: str) -> "InputError":
        """The same complaint under the name the user typed (an option, a file's key)."""
        return InputError(field, self.value, self.allowed)


class Note(UserWarning):
    """Information the user should see, not a fault: a default a design inherits, an automatic
    retry that worked. The CLI shows it as ``softhand VERB: note: ...``."""


class MeshRejected(InputError):
    """A mesh the FEM refuses before solving (elements inverted or folded, a map it cannot
    invert): bad input when the user chose it; a caller that chose the mesh itself (the design
    proof) tries another."""

    def __init__(self, mesh: str, allowed: str):
        super().__init__("mesh", mesh, allowed)


class MeshTooLarge(MeshRejected):
    """A mesh whose FEM would not fit in the machine's memory (refused before meshing)."""
