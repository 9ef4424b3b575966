"""Process set-up shared by every command line: XLA flags, cores, the compile cache,
and the one way a command ends on bad input (one line, a non-zero exit).

Every CLI module (`vccjax.cli`, `search.cli`, `argpred.cli`, `robot.cli`, `vcc.bench`)
uses this module and none of the others. XLA reads its flags and thread pool when JAX
first touches a device, so a command calls `prepare` before it creates any array;
nothing in the packages creates one at import.
"""

from __future__ import annotations

import argparse
import errno
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from vccjax.errors import VCCError

# Exceptions that mean "the user's input or environment is wrong", not "a bug": each ends
# in one line naming the problem. OSError covers unreadable, missing, read-only and full paths.
USER_ERRORS = (VCCError, KeyError, ValueError, NotImplementedError, OSError)


def add_xla_flags(*flags: str) -> None:
    """Append XLA flags (once each) before JAX starts its backend."""
    have = os.environ.get("XLA_FLAGS", "")
    for flag in flags:
        if flag not in have.split():
            have = f"{have} {flag}".strip()
    os.environ["XLA_FLAGS"] = have


def pin_to_cores(n: int) -> None:
    """Keep this process (and the XLA thread pool it will start) on its first n cores."""
    if hasattr(os, "sched_setaffinity"):
        cores = sorted(os.sched_getaffinity(0))
        os.sched_setaffinity(0, set(cores[: max(1, n)]))


def enable_compile_cache() -> None:
    """Keep compiled XLA programs across runs (JAX's persistent cache); VCCJAX_CACHE=off
    turns it off, another value moves it. Every compile is kept, however short: a search
    compiles many small steps, and reloading them halves a warm `vcc learn`."""
    where = os.environ.get("VCCJAX_CACHE", str(Path.home() / ".cache" / "vccjax" / "jax"))
    if where.lower() == "off":
        return
    import jax

    jax.config.update("jax_compilation_cache_dir", where)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)


def prepare(xla_flags: Sequence[str] = (), cores: int | None = None, compile_cache: bool = True) -> None:
    """Set a process up for a command: flags and cores first (before JAX starts), then
    the compile cache."""
    if xla_flags:
        add_xla_flags(*xla_flags)
    if cores is not None:
        pin_to_cores(cores)
    if compile_cache:
        enable_compile_cache()


def error_line(e: BaseException) -> str:
    """One line naming what went wrong and where."""
    if isinstance(e, KeyError) and e.args:
        return str(e.args[0])
    if isinstance(e, OSError) and e.filename is not None:
        what = e.strerror or errno.errorcode.get(e.errno or 0, "cannot be used")
        return f"{e.filename}: {what}"
    return str(e) or type(e).__name__


def run_command(parser: argparse.ArgumentParser, argv: list[str] | None = None,
                prog: str = "vcc") -> int:
    """Parse, run the chosen command (`args.fn`), and turn user errors and Ctrl-C into
    one line on stderr and a non-zero exit status."""
    args = parser.parse_args(argv)
    fn: Callable[[argparse.Namespace], int] = args.fn
    try:
        return int(fn(args) or 0)
    except USER_ERRORS as e:
        print(f"{prog}: error: {error_line(e)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130


def program_from_arg(text: str):
    """A program given on the command line: a file when the argument names an existing
    file (or ends in .vcc/.txt), the program's text otherwise."""
    from vccjax.machine.config import DEFAULT_CONFIG
    from vccjax.machine.program import parse

    looks_like_path = len(text) < 256 and "\n" not in text and ";" not in text
    path = Path(text) if looks_like_path else None
    if path is not None and (text.endswith((".vcc", ".txt")) or path.is_file()):
        if not path.is_file():
            raise VCCError(f"{path}: no such program file")
        text = path.read_text()
    return parse(text, body_max=DEFAULT_CONFIG.body_max)


def provenance(command: str) -> dict:
    """Where and when a measurement was made (UTC date, git commit, machine and JAX
    devices), and the command that made it: what every result file carries."""
    import datetime
    import platform
    import subprocess

    import jax

    cpu = platform.processor()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                cwd=Path(__file__).parent, timeout=10).stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        commit = None
    return {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "commit": commit, "command": command,
        "machine": {"cores": os.cpu_count(), "cpu": cpu, "python": platform.python_version(),
                    "jax": jax.__version__, "devices": [str(d) for d in jax.devices()]},
    }
