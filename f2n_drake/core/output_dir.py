"""Output folders and files written as one unit: all of a run's files, or none of them.

:class:`StagedDir` checks, before any work, that the folder can be written, locks it against a
second writer, and gives a scratch folder beside it; :meth:`StagedDir.commit` renames the
complete scratch folder into place, replacing an earlier output folder as a whole (never merged
with it). :class:`StagedFile` does the same for one file (``--html``). Until commit nothing is
visible; on an exception, Ctrl-C or SIGTERM (see ``run_cli``) the scratch is removed. Scratch
left by a killed process (SIGKILL) is removed by the next writer of the same folder.

A folder that already exists is replaced only when it is empty or carries the ``MARKER`` file
of an earlier output (or, from before the marker, a run's ``graph.json`` or a data set's
``index.json``), so ``--out .`` or ``--out ~`` can never delete someone's files.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from f2n_drake.core.errors import InputError

MARKER = ".f2n_drake_output"
"""Written into every output folder; its presence lets the next run replace the folder."""
SCRATCH_SUFFIX = ".partial"
EARLIER_OUTPUTS = ("graph.json", "index.json")
"""Files by which an output folder written before the marker existed is recognised (a run's,
a data set's)."""


class StagedDir:
    """An output folder staged in a scratch folder beside it (see the module docstring).

    Raises:
        InputError: the path is a file, a symbolic link, the current folder or one above it, a
            folder holding files no f2n_drake command wrote, not writable, or locked by another
            writer.
    """

    def __init__(self, out: str | os.PathLike, *, option: str = "--out") -> None:
        self.path = Path(os.path.abspath(out))
        self._option = option
        self._lock_fd: int | None = None
        self.scratch: Path | None = None
        path, name = self.path, self.path.name
        if path.is_symlink():
            raise InputError(f"{option} {out} is a symbolic link; give the folder itself")
        if path.exists() and not path.is_dir():
            raise InputError(f"output path {out} exists and is not a directory")
        if not name or Path.cwd().resolve().is_relative_to(path.resolve()):
            raise InputError(f"{option} {out} is the current folder or above it; give a new one")
        if path.is_dir():
            entries = {p.name for p in path.iterdir()}
            if entries and not entries & {MARKER, *EARLIER_OUTPUTS}:
                raise InputError(
                    f"{option} {out} holds files an f2n_drake command did not write; "
                    "give a new or empty folder (it is replaced as a whole)"
                )
            if not os.access(path, os.W_OK | os.X_OK):
                raise InputError(f"cannot write to {option} {out}: permission denied")
        parent = path.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            self._lock()
            self._remove_stale_scratch()
            self.scratch = Path(
                tempfile.mkdtemp(prefix=f".{name}.", suffix=SCRATCH_SUFFIX, dir=parent)
            )
            umask = os.umask(0)
            os.umask(umask)
            self.scratch.chmod(0o777 & ~umask)  # mkdtemp's 0700 would become the output's
        except OSError as exc:
            self.close()
            raise InputError(f"cannot write {option} {out}: {exc.strerror or exc}") from exc

    def _lock(self) -> None:
        lock_path = self.path.parent / f".{self.path.name}.lock"
        while True:
            fd = os.open(lock_path, os.O_CREAT | os.O_RDWR, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno in (errno.EAGAIN, errno.EACCES):
                    raise InputError(
                        f"another process is writing {self._option} {self.path}; wait for it "
                        "to finish or give another folder"
                    ) from None
                raise
            try:
                same = os.stat(lock_path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:  # else the holder removed it between our open and flock: try again
                self._lock_fd, self._lock_path = fd, lock_path
                return
            os.close(fd)

    def _remove_stale_scratch(self) -> None:
        pattern = f".{self.path.name}.*{SCRATCH_SUFFIX}"
        for stale in self.path.parent.glob(pattern):
            shutil.rmtree(stale, ignore_errors=True)

    def commit(self) -> None:
        """Put the scratch folder in place of the output folder (one rename; an earlier output
        folder is moved aside first and removed after)."""
        if self.scratch is None:
            raise RuntimeError("output folder already committed or closed")
        (self.scratch / MARKER).write_text(
            "Written by f2n_drake. The next command writing this folder replaces it as a whole.\n"
        )
        old = None
        if self.path.exists():  # renamed over an empty scratch-named folder, removed below
            old = tempfile.mkdtemp(
                prefix=f".{self.path.name}.", suffix=SCRATCH_SUFFIX, dir=self.path.parent
            )
            os.replace(self.path, old)
        os.replace(self.scratch, self.path)
        self.scratch = None
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)

    def close(self) -> None:
        """Remove the scratch folder (if not committed) and release the lock."""
        if self.scratch is not None:
            shutil.rmtree(self.scratch, ignore_errors=True)
            self.scratch = None
        if self._lock_fd is not None:
            with contextlib.suppress(OSError):
                os.unlink(self._lock_path)
            os.close(self._lock_fd)
            self._lock_fd = None

    def __enter__(self) -> StagedDir:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


class StagedFile:
    """One output file written to a scratch file beside it and renamed into place on commit.

    Raises:
        InputError: the path is a folder, its folder is missing, or the folder is not writable.
    """

    def __init__(self, path: str | os.PathLike, *, option: str) -> None:
        self.path = Path(os.path.abspath(path))
        if self.path.is_dir():
            raise InputError(f"{option} {path} is a folder; give a file path")
        if not self.path.parent.is_dir():
            raise InputError(f"{option} {path}: its folder {self.path.parent} does not exist")
        try:
            fd, scratch = tempfile.mkstemp(
                prefix=f".{self.path.name}.", suffix=SCRATCH_SUFFIX, dir=self.path.parent
            )
        except OSError as exc:
            raise InputError(f"cannot write {option} {path}: {exc.strerror or exc}") from exc
        os.close(fd)
        self.scratch: Path | None = Path(scratch)

    def commit(self) -> None:
        if self.scratch is not None:
            os.replace(self.scratch, self.path)
            self.scratch = None

    def close(self) -> None:
        if self.scratch is not None:
            self.scratch.unlink(missing_ok=True)
            self.scratch = None

    def __enter__(self) -> StagedFile:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


def check_writable_file(path: str | os.PathLike, *, option: str) -> None:
    """Check, before the work that makes it, that the file ``path`` can be written: not a
    folder, its folder (created if missing) writable.

    Raises:
        InputError: otherwise, naming the option.
    """
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{option} {path} is a folder; give a file path")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot write {option} {path}: {exc.strerror or exc}") from exc
    StagedFile(path, option=option).close()


@contextlib.contextmanager
def atomic_output_dir(out: str | os.PathLike, *, option: str = "--out") -> Iterator[Path]:
    """Yield a scratch folder that replaces ``out`` as a whole only if the block succeeds.

    Raises:
        InputError: as :class:`StagedDir`.
    """
    with StagedDir(out, option=option) as staged:
        yield staged.scratch
        staged.commit()
