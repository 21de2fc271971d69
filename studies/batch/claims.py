"""Per-case claims, so that concurrent runs of one study compute every case once.

A claim is an exclusive ``flock`` on ``<study>/.claims/<case key>.lock``. The kernel
drops it when the holder closes the file or dies (even by SIGKILL), so a crashed run
never leaves a case locked. Lock files are never removed (removing one while another
process waits on it would let two processes hold "the" lock). Claims are only ever
tried without blocking; a run that finds a case claimed comes back to it later, so no
two runs can wait on each other.
"""
from __future__ import annotations

import errno
import fcntl
import os
from pathlib import Path


class Claims:
    """The claims this process holds in one study folder."""

    def __init__(self, study_dir: Path):
        self.folder = Path(study_dir) / ".claims"
        self.held: dict[str, int] = {}

    def try_claim(self, key: str) -> bool:
        """Claim case ``key`` if no other process holds it; True if this process now does."""
        if key in self.held:
            return True
        path = self.folder / f"{key}.lock"
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            if self.folder.is_symlink():
                raise OSError(errno.ELOOP, "a symbolic link, not followed out of the study's folder")
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o666)
        except OSError as exc:  # damaged or read-only state: one line, not a traceback
            from softhand.reduced.vocabulary.errors import InputError

            raise InputError("--results", str(path), f"cannot hold the case's claim lock ({exc.strerror or exc}); "
                             "remove what stands there or make the study's folder writable") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            return False
        self.held[key] = fd
        return True

    def release(self, key: str) -> None:
        fd = self.held.pop(key, None)
        if fd is not None:
            os.close(fd)

    def release_all(self) -> None:
        for key in list(self.held):
            self.release(key)
