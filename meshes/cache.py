"""A cache of generated meshes, so the same mesh is never generated twice.

The key is a hash of (the geometry function's module and name, its parameters, the
element size, the element order, the gmsh version, the softhand version, :data:`FORMAT`).
Files live in ``$SOFTHAND_CACHE/meshes`` (default ``~/.cache/softhand/meshes``) and are
written atomically, so concurrent workers asking for the same mesh at worst both generate
it. Each ``.msh`` has a ``.msh.sha256`` next to it; a mesh whose checksum does not match
(truncated, edited, swapped; the checksum file names its mesh, so an entry copied over
another with its checksum is not used either) is generated again. A cache folder that
cannot be written is a warning: the mesh is generated into a temporary folder instead,
removed when the process exits.
"""
from __future__ import annotations

import atexit
import dataclasses
import hashlib
import json
import os
import shutil
import stat
import sys
import tempfile
from pathlib import Path

import skfem

from softhand.meshes.convert import read_mesh
from softhand.meshes.gmsh_io import GMSH_VERSION, Geometry, generate_msh

#: bump when the way meshes are generated changes, to invalidate old cache entries
FORMAT = 2  # 2: element size no longer capped by gmsh's default point sizes


def cache_dir() -> Path:
    """The mesh cache folder: ``$SOFTHAND_CACHE/meshes`` or ``~/.cache/softhand/meshes``; with
    no home folder (HOME unset or empty, and a user id the password file does not know, as in
    a container run as another user) ``<temp>/softhand-<uid>/meshes``."""
    root = os.environ.get("SOFTHAND_CACHE")
    if not root:
        try:
            home = Path.home() if os.environ.get("HOME", None) != "" else None
        except RuntimeError:  # "Could not determine home directory"
            home = None
        root = home / ".cache" / "softhand" if home is not None else \
            Path(tempfile.gettempdir()) / f"softhand-{os.getuid() if hasattr(os, 'getuid') else 'user'}"
    return Path(root) / "meshes"


def mesh_key(geometry: Geometry, params, *, size: float, order: int, refine: int = 0) -> str:
    """A stable hex digest naming this mesh."""
    fields = dataclasses.asdict(params) if dataclasses.is_dataclass(params) else dict(params)
    blob = json.dumps({
        "geometry": f"{geometry.__module__}.{geometry.__qualname__}",
        "params": fields, "size": float(size), "order": int(order),
        **({"refine": int(refine)} if refine else {}),
        "gmsh": GMSH_VERSION, "softhand": _softhand_version(), "format": FORMAT,
    }, sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()[:20]


def _softhand_version() -> str:
    from softhand.reduced.vocabulary.versions import package_version

    return package_version()


#: the largest mesh file the cache reads (a finger of the finest mesh a machine can solve is
#: a few hundred MB); a larger entry is no mesh of ours
MAX_MESH_BYTES = 2 << 30


def _sha256(path: Path) -> str:
    """The SHA-256 of the regular file ``path`` (a FIFO or a folder: OSError, never a wait)."""
    sha = hashlib.sha256()
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(f"{path}: not a regular file")
        with os.fdopen(fd, "rb", closefd=False) as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                sha.update(block)
    finally:
        os.close(fd)
    return sha.hexdigest()


def _checksum_line(path: Path) -> str:
    """The content of a mesh's checksum file: the mesh's SHA-256 and its own name (an entry
    copied over another together with its checksum names the other mesh, and is not used)."""
    return f"{_sha256(path)}  {path.name}"


def valid_entry(path: Path) -> bool:
    """True if the cached mesh ``path`` is there, a regular file of bounded size, and matches
    its recorded checksum and name."""
    try:
        checksum = Path(f"{path}.sha256")
        if not (path.is_file() and checksum.is_file()) or checksum.stat().st_size > 1024 \
                or path.stat().st_size > MAX_MESH_BYTES:
            return False
        with open(checksum, "rb") as f:
            recorded = f.read(1024).decode().strip()
        return recorded == _checksum_line(path)
    except (OSError, ValueError):
        return False


def _named_checksum(path: Path) -> bool:
    """Whether the checksum file of ``path`` is of this format (checksum and name), not the
    earlier one (the checksum alone)."""
    checksum = Path(f"{path}.sha256")
    try:
        if not checksum.is_file():  # none, a FIFO, a folder: the warning says the entry is not used
            return True
        with open(checksum, "rb") as f:
            return len(f.read(1024).split()) == 2
    except OSError:
        return True


def cached_msh(geometry: Geometry, params, *, size: float, order: int = 2, refine: int = 0,
               folder: str | Path | None = None) -> Path:
    """The ``.msh`` file of this geometry; generated with gmsh only if not cached (and valid)."""
    name = f"{geometry.__name__}-{mesh_key(geometry, params, size=size, order=order, refine=refine)}.msh"
    path = (Path(folder) if folder is not None else cache_dir()) / name
    if valid_entry(path):
        return path
    if path.exists() and _named_checksum(path):  # an entry of an earlier format: quietly replaced
        print(f"softhand: warning: cached mesh {name} does not match its checksum; "
              f"generating it again", file=sys.stderr)
    try:
        generate_msh(geometry, params, path, size=size, order=order, refine=refine)
        from softhand.meshes.atomic import atomic_path

        with atomic_path(f"{path}.sha256") as tmp:
            tmp.write_text(_checksum_line(path) + "\n")
    except OSError as exc:
        print(f"softhand: warning: the mesh cache {path.parent} cannot be written "
              f"({exc.strerror or exc}); the mesh is not cached", file=sys.stderr)
        path = _scratch_folder() / name
        generate_msh(geometry, params, path, size=size, order=order, refine=refine)
    return path


def _scratch_folder() -> Path:
    """A temporary folder for the meshes of a cache that cannot be written, removed when this
    process exits (and, after a SIGKILL, by the next process that needs one)."""
    for folder in Path(tempfile.gettempdir()).glob("softhand-mesh-*-*"):
        pid = folder.name.split("-")[2]
        try:
            if pid.isdigit() and folder.lstat().st_uid == os.getuid() and not folder.is_symlink():
                os.kill(int(pid), 0)
        except ProcessLookupError:
            shutil.rmtree(folder, ignore_errors=True)
        except OSError:
            continue
    folder = Path(tempfile.mkdtemp(prefix=f"softhand-mesh-{os.getpid()}-"))
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    return folder


def discard(path: Path, folders=()) -> None:
    """Remove the cache entry ``path`` (a mesh this process made and the FEM refuses) and the
    ``folders`` it made for it, if empty (innermost first)."""
    for name in (f"{path}.sha256", str(path)):
        Path(name).unlink(missing_ok=True)
    for folder in folders:
        try:
            Path(folder).rmdir()
        except OSError:
            break


def load_mesh(geometry: Geometry, params, *, size: float, order: int = 2, refine: int = 0,
              folder: str | Path | None = None) -> skfem.Mesh:
    """A scikit-fem mesh (named boundaries/subdomains) of this geometry, through the cache."""
    return read_mesh(cached_msh(geometry, params, size=size, order=order, refine=refine,
                                folder=folder))
