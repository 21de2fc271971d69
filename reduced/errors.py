"""The one error type for bad user input, shared by every layer.

The CLI turns an :class:`InputError` into one line on stderr and exit code 2.
"""
from __future__ import annotations


class InputError(ValueError):
    """Bad user input: names the field, the value given and what is allowed."""

    def __init__(self, field: str, value, allowed: str):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{field} = {value!r}: {allowed}")
