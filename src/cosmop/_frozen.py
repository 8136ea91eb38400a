"""Pickling for frozen dataclasses that hold read-only mappings (``MappingProxyType``).

``MappingProxyType`` cannot be pickled, so such values could not cross into worker processes.
:func:`reduce_frozen` rebuilds the object from its init fields with plain dicts; the class's
``__post_init__`` makes them read-only again.
"""

from __future__ import annotations

from dataclasses import fields
from types import MappingProxyType
from typing import Any


def reduce_frozen(obj: Any) -> tuple[type, tuple[Any, ...]]:
    """``__reduce__`` for a frozen dataclass whose mapping fields are read-only proxies."""
    args = tuple(
        dict(value) if isinstance(value, MappingProxyType) else value
        for value in (getattr(obj, f.name) for f in fields(obj) if f.init)
    )
    return type(obj), args
