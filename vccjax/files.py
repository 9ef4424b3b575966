"""Files someone relies on: written whole or not at all, checked writable before the
work starts, and one writer per run folder.

A kill in the middle of a plain write leaves a cut file that a resume or a reader then
trusts, so every result, manifest, card, weight file, picture and report goes through
a temporary file in the same folder that is renamed over the target at once (a rename
within a folder is atomic). Logs (JSON lines) are only appended to, a whole line per
write (`vccjax.records`).

Two processes writing one run folder would each append every record; a lock on the
folder (`hold`) makes the second one stop with a line naming the first. The lock is an
`flock` on a file named after the folder's full path in a per-user lock folder (not in
the folder itself, so a refused command leaves nothing behind), and it goes away with
its process, however that ends.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import sys
from collections.abc import Iterator
from pathlib import Path

from vccjax.errors import VCCError

LOCK_NAME = ".vcc.lock"
_held: dict[Path, int] = {}  # lock file -> its open descriptor, kept for the process's life


def _temporary(path: Path) -> Path:
    """A private temporary name beside `path`, keeping its suffix (image writers pick
    the format from it)."""
    return path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")


@contextlib.contextmanager
def whole(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path to write; on success it replaces `path` at once, on any
    failure it is removed and `path` is left as it was."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _temporary(path)
    try:
        yield tmp
        if not tmp.exists():
            raise OSError(f"{path}: the writer produced no file")
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)


def write_whole(path: str | Path, data: str | bytes) -> None:
    """Write `data` to `path` whole or not at all."""
    with whole(path) as tmp:
        if isinstance(data, str):
            tmp.write_text(data)
        else:
            tmp.write_bytes(data)


def write_json(path: str | Path, content, indent: int | None = 1, sort_keys: bool = False) -> None:
    """Write `content` as JSON whole or not at all; NaN and infinities are refused
    (they are not JSON, and a reader would choke on them)."""
    write_whole(path, json.dumps(content, indent=indent, sort_keys=sort_keys, allow_nan=False) + "\n")


def check_writable(path: str | Path, what: str = "output", folder: bool = False) -> Path:
    """Refuse, before any work, an output path that could not be written: its nearest
    existing ancestor must be a writable folder, and the path itself must not be a
    folder where a file is meant (or a file where a folder is meant)."""
    p = Path(path)
    if str(path).strip() == "":
        raise VCCError(f"the {what} path is empty")
    if p.exists():
        if folder and not p.is_dir():
            raise VCCError(f"{p}: the {what} folder is a file")
        if not folder and p.is_dir():
            raise VCCError(f"{p}: the {what} is a folder, not a file")
    up = p if folder and p.exists() else p.parent
    while not up.exists():
        up = up.parent
    if not up.is_dir():
        raise VCCError(f"{p}: cannot write the {what}: {up} is not a folder")
    if not os.access(up, os.W_OK | os.X_OK):
        raise VCCError(f"{p}: cannot write the {what}: {up} is not writable")
    if str(up.resolve()).startswith(("/proc", "/sys")):
        raise VCCError(f"{p}: cannot write the {what} under {up}")
    return p


def hold(folder: str | Path, what: str = "run folder", name: str = LOCK_NAME) -> None:
    """Take the folder's lock (`name`: one folder may have several, such as a suite's
    shards) for the rest of this process, or stop with a line naming the process that
    holds it. Taking it twice in one process is a no-op."""
    import fcntl
    import hashlib
    import tempfile

    folder = Path(folder).resolve()
    locks = Path(tempfile.gettempdir()) / f"vccjax-locks-{os.getuid()}"
    locks.mkdir(mode=0o700, exist_ok=True)
    lock = locks / f"{hashlib.sha256(str(folder / name).encode()).hexdigest()[:32]}.lock"
    if lock in _held:
        return
    fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        holder = os.read(fd, 4096).decode(errors="replace").strip() or "another process"
        os.close(fd)
        raise VCCError(f"{folder}: this {what} is in use by {holder}; wait for it to end "
                       "or stop it, then rerun") from None
    os.ftruncate(fd, 0)
    program = Path(sys.argv[0]).name if sys.argv and sys.argv[0] else "python"
    command = " ".join(["vcc" if program == "__main__.py" else program, *sys.argv[1:]])
    os.write(fd, f"pid {os.getpid()} on {socket.gethostname()} ({command})\n".encode())
    _held[lock] = fd
    if folder.is_dir():
        clear_stale(folder)


def clear_stale(folder: Path) -> None:
    """Remove temporaries left in `folder` by writers that were killed (their process is
    gone); a live writer's temporary is left alone."""
    for tmp in folder.glob(".*.tmp*"):
        pid = tmp.name.rsplit(".tmp", 1)[0].rsplit(".", 1)[-1]
        if pid.isdigit() and not _alive(int(pid)):
            tmp.unlink(missing_ok=True)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def check_readable(path: str | Path, what: str = "file") -> Path:
    """Refuse an input that is not a regular file (a folder, a device, a pipe that would
    block the read forever) with a line naming it."""
    p = Path(path)
    if not p.exists():
        raise VCCError(f"{p}: no such {what}")
    if p.is_dir():
        raise VCCError(f"{p}: a folder, not a {what}")
    if not p.is_file():
        raise VCCError(f"{p}: not a regular file (a pipe or a device); give a {what}")
    return p
