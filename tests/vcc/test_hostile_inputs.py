"""Hostile input over every `vcc` command, each case run through the real CLI as a
subprocess (the table is `tests/vcc/hostile_cases.py`).

Every case must end (1) with a non-zero exit code, (2) without a traceback (nor the
CLI's "internal error" line, a crash whose traceback went to a file), (3) with exactly
one non-empty line on stderr, (4) within TIMEOUT seconds, and (5) without a half-written
file: each path in the case's "writes" is afterwards absent or byte-for-byte what it was
before (a folder: the same entries, each the same), and no temporary file (`*.tmp*`,
`.*.tmp`) is left anywhere in its folder.

A case runs in its own temporary folder (the cwd), with HOME and VCC_LIBRARY inside it,
VCCJAX_CACHE=off, JAX_PLATFORMS=cpu, stdin closed, in its own session (a timeout kills
the whole group) and under an address-space limit (a case that asks for absurd sizes
fails instead of taking the machine's memory). Set VCC_HOSTILE_LOG=FILE to get one JSON
line per case (argv, exit code, seconds, stderr's first and last line, problems).
"""

from __future__ import annotations

import fnmatch
import json
import os
import re
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.vcc.hostile_cases import CASES
from tests.vcc.hostile_files import MEMORY_LIMIT, REPO, TIMEOUT, _sha, base, expand, templates
from tests.vcc.hostile_folders import SETUPS


# ---- checks -------------------------------------------------------------------------------
def snapshot(path: Path):
    """None when absent; a file's sha256; a folder's sorted (relative path, sha256) list."""
    if not os.path.lexists(path):
        return None
    if path.is_symlink():
        return ("link", os.readlink(path))
    if path.is_dir():
        return sorted((str(p.relative_to(path)), _sha(p) if p.is_file() and not p.is_symlink() else "-")
                      for p in path.rglob("*"))
    if path.is_file():
        return _sha(path)
    return ("special", path.stat().st_mode)


def describe_change(before, after) -> str:
    """What became of a path in words: created, removed, changed, and for a folder which
    entries came, went or changed."""
    if before is None:
        if isinstance(after, list):
            return "folder created" + (f" holding {', '.join(n for n, _ in after[:6])}" if after else " (empty)")
        return "created"
    if after is None:
        return "removed"
    if isinstance(before, list) and isinstance(after, list):
        b, a = dict(before), dict(after)
        parts = []
        for label, names in (("added", [n for n in a if n not in b]), ("removed", [n for n in b if n not in a]),
                             ("changed", [n for n in a if n in b and a[n] != b[n]])):
            if names:
                parts.append(f"{label} {', '.join(names[:6])}")
        return "; ".join(parts) or "changed"
    if isinstance(before, tuple) and before[0] == "link":
        return "the symlink was replaced" if after != before else "unchanged"
    return "changed"


def leftover_temporaries(tmp: Path) -> list[str]:
    out = []
    for root, dirs, files in os.walk(tmp):
        for name in files + dirs:
            if fnmatch.fnmatch(name, "*.tmp*") or fnmatch.fnmatch(name, ".*.tmp"):
                out.append(str(Path(root, name).relative_to(tmp)))
    return sorted(out)


def exception_type(text: str) -> str | None:
    """The exception a traceback ends with."""
    if "Traceback" not in text:
        return None
    names = re.findall(r"^([A-Za-z_][\w.]*(?:Error|Exception|Exit|Interrupt|Warning|Overflow)\w*)(?::|$)", text,
                       re.MULTILINE)
    return names[-1] if names else "?"


def _limits() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def run_case(case: dict, tmp: Path) -> dict:
    base(tmp)
    setups = case.get("setup") or []
    for name in [setups] if isinstance(setups, str) else setups:
        SETUPS[name](tmp)
    names = templates(tmp)
    argv = [expand(a, names) for a in case["argv"]]
    writes = [Path(expand(w, names)) for w in case.get("writes", [])]
    before = {w: snapshot(w) for w in writes}
    temporaries_before = set(leftover_temporaries(tmp))
    env = {k: v for k, v in os.environ.items() if not k.startswith(("VCC", "PYTEST", "XDG_"))}
    env.update(VCCJAX_CACHE="off", JAX_PLATFORMS="cpu", HOME=str(tmp / "home"), VCC_LIBRARY=str(tmp / "library"),
               PYTHONPATH=str(REPO))
    env.update({k: expand(v, names) for k, v in case.get("env", {}).items()})
    start = time.monotonic()
    proc = subprocess.Popen([sys.executable, "-m", "vcc", *argv], cwd=tmp, env=env, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
                            preexec_fn=_limits)
    hung = False
    try:
        out, err = proc.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        hung = True
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
    seconds = time.monotonic() - start
    out_text, err_text = out.decode(errors="replace"), err.decode(errors="replace")
    lines = [line for line in err_text.strip().splitlines()]
    problems = []
    if hung:
        problems.append(f"hang: still running after {TIMEOUT:.0f} s")
    elif proc.returncode == 0:
        problems.append("exit 0")
    if "Traceback" in out_text + err_text:
        problems.append(f"traceback: {exception_type(out_text + err_text)}")
    crash = re.search(r"internal error[^:]*: ([A-Za-z_][\w.]*)", err_text)
    if crash:  # a crash turned into one line is still a crash: the traceback went to a file
        problems.append(f"internal error: {crash.group(1)}")
    if not hung and (len(lines) != 1 or not lines[0].strip()):
        problems.append(f"stderr has {len(lines)} lines, not one")
    for w in writes:
        after = snapshot(w)
        if after != before[w]:
            problems.append(f"half-written: {w.relative_to(tmp) if w.is_relative_to(tmp) else w}: "
                            f"{describe_change(before[w], after)}")
    left = sorted(set(leftover_temporaries(tmp)) - temporaries_before)
    if left:
        problems.append(f"half-written: temporary files left: {', '.join(left[:5])}")
    result = {"id": case["id"], "argv": argv, "rc": proc.returncode, "seconds": round(seconds, 2),
              "stderr_lines": len(lines), "first": lines[0][:300] if lines else "",
              "last": lines[-1][:300] if lines else "", "stdout_tail": out_text.strip()[-200:],
              "problems": problems, "slow": bool(case.get("slow"))}
    log = os.environ.get("VCC_HOSTILE_LOG")
    if log:
        with open(log, "a") as f:
            f.write(json.dumps(result) + "\n")
    return result


# The default suite runs one quick case in DEFAULT_EVERY (a spread over every command,
# about 1.5 s each); `-m slow` runs all the others, so the two together are the table.
DEFAULT_EVERY = 10


def _param(case: dict, index: int):
    slow = case.get("slow") or index % DEFAULT_EVERY
    return pytest.param(case, id=case["id"], marks=[pytest.mark.slow] if slow else [])


def test_case_ids_are_unique():
    ids = [c["id"] for c in CASES]
    assert len(ids) == len(set(ids)), sorted({i for i in ids if ids.count(i) > 1})
    unknown = {s for c in CASES for s in ([c["setup"]] if isinstance(c.get("setup"), str) else c.get("setup", []))
               if s not in SETUPS}
    assert not unknown, unknown


@pytest.mark.parametrize("case", [_param(c, i) for i, c in enumerate(CASES)])
def test_hostile_input(case, tmp_path):
    r = run_case(case, tmp_path)
    assert not r["problems"], (
        f"{r['id']}: {'; '.join(r['problems'])}\n  argv: {r['argv']}\n  exit {r['rc']} after {r['seconds']} s\n"
        f"  stderr first: {r['first']}\n  stderr last:  {r['last']}"
    )
