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
import math
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


def cluster_flags(parser: argparse.ArgumentParser, what: str) -> None:
    """`--cluster` and `--workers`, spelt alike by every command that can hand its work
    to Ray workers; `what` says what `--cluster ray` does there."""
    parser.add_argument("--cluster", choices=["none", "ray"], default="none",
                        help=f"'ray': {what} (joins $RAY_ADDRESS, or starts a local cluster; docs/cluster.md)")
    parser.add_argument("--workers", type=count(1, 4096),
                        help="Ray workers, one core each (default: one per CPU of the cluster)")


def on_cluster(a: argparse.Namespace) -> bool:
    """Whether the command runs on Ray (`cluster_flags`): `--workers` without `--cluster
    ray` is refused, and a missing Ray extra fails now, before any work, with its message."""
    if a.workers is not None and a.cluster != "ray":
        raise ValueError("--workers: only with --cluster ray")
    if a.cluster == "ray":
        from vccjax.actor_pool import ray_module

        ray_module()
    return a.cluster == "ray"


def count(low: int = 1, high: int | None = None) -> Callable[[str], int]:
    """An argparse type: a whole number from `low` to `high`, checked when the command
    line is read (before any work)."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
        if value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(
                f"{value} is out of range: give {low} or more" if high is None else
                f"{value} is out of range: give {low} to {high}")
        return value
    parse.__name__ = "whole number"
    return parse


def counts(low: int = 1, high: int | None = None, none_ok: bool = False) -> Callable[[str], str]:
    """An argparse type: comma-separated whole numbers from `low` to `high`, at least one
    unless `none_ok` (an empty text then means none); kept as the text, which the command
    splits."""
    one = count(low, high)

    def parse(text: str) -> str:
        if none_ok and text == "":
            return text
        items = [t.strip() for t in text.split(",")]
        if not text.strip() or any(not t for t in items):
            raise argparse.ArgumentTypeError(f"'{text}' has an empty item; give numbers separated by commas")
        for t in items:
            one(t)
        return ",".join(items)
    parse.__name__ = "list of whole numbers"
    return parse


def number(low: float | None = None, high: float | None = None, above: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite number from `low` (or above it, when `above`) to `high`."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{text} is not a finite number")
        too_low = low is not None and (value <= low if above else value < low)
        if too_low or (high is not None and value > high):
            lo = "" if low is None else (f"above {low:g}" if above else f"at least {low:g}")
            hi = "" if high is None else f"at most {high:g}"
            bounds = " and ".join(x for x in (lo, hi) if x)
            raise argparse.ArgumentTypeError(f"{value:g} is out of range: give a number {bounds}")
        return value
    parse.__name__ = "number"
    return parse


def name_list(text: str) -> str:
    """An argparse type: a comma-separated list of names, none empty; a name given twice
    is kept once (in its first place)."""
    items = [t.strip() for t in text.split(",")]
    if not text.strip() or any(not t for t in items):
        raise argparse.ArgumentTypeError(f"'{text}' has an empty name; give names separated by commas")
    return ",".join(dict.fromkeys(items))


name_list.__name__ = "list of names"


def out_file(*suffixes: str, several: bool = False) -> Callable[[str], str]:
    """An argparse type: a file to write (or, with `several`, files separated by commas),
    of one of `suffixes` (any when none), whose folder can be written: checked when the
    command line is read, not after the work."""
    def parse(text: str) -> str:
        names = text.split(",") if several else [text]
        if not all(n.strip() for n in names):
            raise argparse.ArgumentTypeError(f"'{text}' has an empty file name")
        for name in names:
            if suffixes and Path(name).suffix.lower() not in suffixes:
                raise argparse.ArgumentTypeError(f"{name}: write {' or '.join(suffixes)}")
            _writable(name, folder=False)
        return text
    parse.__name__ = "output file"
    return parse


def out_folder(text: str) -> str:
    """An argparse type: a folder to write (made if missing), checked when the command
    line is read."""
    return _writable(text, folder=True)


out_folder.__name__ = "output folder"


def _writable(text: str, folder: bool) -> str:
    from vccjax import files

    try:
        files.check_writable(text, "output", folder=folder)
    except VCCError as e:
        raise argparse.ArgumentTypeError(str(e)) from None
    return text


class _StoreOnce(argparse._StoreAction):
    """An option that takes one value refuses a second (`--seed 1 --seed 2` is a slip,
    not a choice of the last)."""

    def __call__(self, parser, namespace, values, option_string=None):
        if option_string is not None:
            given = namespace.__dict__.setdefault(_GIVEN, set())
            if self.dest in given:
                parser.error(f"{'/'.join(self.option_strings)} given twice; give it once")
            given.add(self.dest)
        super().__call__(parser, namespace, values, option_string)


_GIVEN = "_options_given"


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (what is wrong, and where to read
    more), exit status 2, and whose single-valued options may be given once; every
    subcommand's parser is of this class too."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.register("action", None, _StoreOnce)
        self.register("action", "store", _StoreOnce)

    def parse_known_args(self, args=None, namespace=None):
        parsed, rest = super().parse_known_args(args, namespace)
        parsed.__dict__.pop(_GIVEN, None)
        return parsed, rest

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def run_command(parser: argparse.ArgumentParser, argv: list[str] | None = None,
                prog: str = "vcc") -> int:
    """Parse, run the chosen command (`args.fn`), and end every failure in one line on
    stderr: bad input or a file that cannot be used (exit 2), Ctrl-C (130), and anything
    else as a bug whose traceback is saved to a file the line names (exit 70)."""
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:  # a bad option (one line already printed), or --help
        return int(e.code or 0) if isinstance(e.code, int) or e.code is None else 2
    fn: Callable[[argparse.Namespace], int] = args.fn
    before = _catch_interrupts()
    try:
        return int(fn(args) or 0)
    except BrokenPipeError:  # the reader went away (`vcc concepts | head`): nothing to say (an OSError,
        _quiet_stdout()      # so taken before USER_ERRORS)
        return 0
    except USER_ERRORS as e:
        print(f"{prog}: error: {error_line(e)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{prog}: interrupted; rerun the same command to resume", file=sys.stderr)
        return 130
    except MemoryError:
        print(f"{prog}: error: out of memory; try smaller sizes or counts", file=sys.stderr)
        return 2
    except Exception as e:  # noqa: BLE001 - the last resort: one line, the traceback kept
        print(f"{prog}: internal error (a bug, please report it): {type(e).__name__}: {str(e)[:200]}; "
              f"traceback saved to {save_traceback()}", file=sys.stderr)
        return 70
    finally:
        if before is not None:
            import signal

            signal.signal(signal.SIGINT, before)


def _quiet_stdout() -> None:
    """Point stdout at /dev/null: the reader of the pipe is gone, and Python's flush at
    exit would otherwise fail on it again and print that it did."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # stdout is no file (a test's capture): nothing to quiet
        pass


def _catch_interrupts():
    """Ctrl-C as `on_interrupt` takes it, for the command's run; the handler it replaces
    (None where signals cannot be set: not the main thread)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return None
    return signal.signal(signal.SIGINT, on_interrupt)


def on_interrupt(signum: int, frame) -> None:
    """Ctrl-C as KeyboardInterrupt, except where Python would print the exception and drop
    it: inside a garbage-collector callback (JAX registers one) or an object's `__del__`.
    The search then went on to its end and reported a verdict on a fraction of its
    budget. There, the signal is sent again a moment later, when the callback is done."""
    import gc

    callbacks = {getattr(cb, "__code__", None) for cb in gc.callbacks}
    f = frame
    while f is not None:
        if f.f_code in callbacks or f.f_code.co_name == "__del__":
            send_again()
            return
        f = f.f_back
    raise KeyboardInterrupt


def send_again(delay: float = 0.05) -> None:
    import signal
    import threading

    timer = threading.Timer(delay, os.kill, (os.getpid(), signal.SIGINT))
    timer.daemon = True
    timer.start()


def save_traceback() -> str:
    """Write the current exception's traceback to a file and return its path."""
    import tempfile
    import time
    import traceback

    text = traceback.format_exc()
    for where in (Path.home() / ".cache" / "vccjax" / "crashes", Path(tempfile.gettempdir())):
        try:
            where.mkdir(parents=True, exist_ok=True)
            path = where / f"vcc-crash-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}.txt"
            path.write_text(text)
            return str(path)
        except OSError:
            continue
    return "nowhere (no writable folder)"


def program_from_arg(text: str):
    """A program given on the command line: a file when the argument names an existing
    file (or ends in .vcc/.txt), the program's text otherwise."""
    from vccjax.machine.config import DEFAULT_CONFIG
    from vccjax.machine.program import parse

    looks_like_path = len(text) < 256 and "\n" not in text and ";" not in text
    path = Path(text) if looks_like_path else None
    if path is not None and path.is_dir():
        raise VCCError(f"{path}: a folder, not a program (give its text, or a .vcc file)")
    if path is not None and (text.endswith((".vcc", ".txt")) or path.is_file()):
        if not path.is_file():
            raise VCCError(f"{path}: no such program file")
        try:
            text = path.read_text()
        except UnicodeDecodeError:
            raise VCCError(f"{path}: not a text file (a program is text)") from None
        try:
            return parse(text, body_max=DEFAULT_CONFIG.body_max)
        except VCCError as e:
            raise type(e)(f"{path}: {e}") from None
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
