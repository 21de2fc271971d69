"""Installed package versions, for cache keys and provenance records."""
from __future__ import annotations

from functools import lru_cache


@lru_cache(maxsize=None)
def package_version(name: str = "softhand", missing: str = "unknown") -> str:
    """The installed version of distribution ``name``; ``missing`` when it is not installed."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(name)
    except PackageNotFoundError:
        return missing
