"""The grasp weights' disk cache (:func:`softhand.studies.weights.weights` reads and fills it): where
it lives, the format of its entries, and reading (checked: format, key, schema, checksum) and
writing them.
"""
from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

from softhand.studies.io.files import json_text, jsonable, read_bounded, write_json

#: bump when the FEM or the result's fields change, to invalidate cached results
CACHE_FORMAT = 6  # 6: the pressure named P_cavity_MPa, eq. (25)'s F_v_reduced_note; 5: entries {format, key, sha256, result}; 4: factorisations counted; 3: the finger's windings on their own degree-5 rule, mesh graded at the ring edges


def cache_dir():
    """``$SOFTHAND_CACHE/weights`` (default ``~/.cache/softhand/weights``), next to the meshes."""
    from softhand.meshes.cache import cache_dir as mesh_cache_dir

    return mesh_cache_dir().parent / "weights"


#: keys and types every cached result has
_SCHEMA = {"w": list, "w_sum": float, "theta_deg": float, "F_v_fem_N": float,
           "diameter_mm": float, "mesh_size_mm": float, "ndofs": int}


def _checksum(result: dict) -> str:
    return hashlib.sha256(json.dumps(result, sort_keys=True, default=jsonable).encode()).hexdigest()


#: the largest cache entry read (one grasp's numbers: a few kB)
MAX_ENTRY_BYTES = 1 << 20


def read_entry(path: Path, key: str) -> dict | None:
    """The cached result at ``path`` if it is there and valid (format, key, schema, checksum)."""
    if not (path.exists() or path.is_symlink()):
        return None
    try:
        entry = json.loads(read_bounded(path, MAX_ENTRY_BYTES))  # a FIFO: refused, not waited on
        result = entry["result"]
        valid = (entry["format"] == CACHE_FORMAT and entry["key"] == key
                 and entry["sha256"] == _checksum(result)
                 and all(isinstance(result.get(k), t if t is not float else (int, float))
                         for k, t in _SCHEMA.items()))
    except (OSError, ValueError, KeyError, TypeError, RecursionError):  # RecursionError: nested deep
        valid = False
    if valid:
        return result
    print(f"softhand: warning: invalid cache entry {path.name}; recomputing it", file=sys.stderr)
    return None


def write_entry(path: Path, key: str, result: dict) -> None:
    """Cache ``result`` with its format, key and checksum; a failure to write is a warning."""
    result = json.loads(json_text(result))  # as it reads back
    try:
        write_json(path, {"format": CACHE_FORMAT, "key": key, "sha256": _checksum(result),
                          "result": result})
    except OSError as exc:
        print(f"softhand: warning: the result is not cached ({path.parent}: "
              f"{exc.strerror or exc})", file=sys.stderr)
