"""A simulated arm (MuJoCo, batched on MJX) that carries out VCC programs from a camera image."""

import contextlib
import importlib.abc
import io
import os
import re
import sys

os.environ.setdefault("MUJOCO_GL", "egl")  # offscreen rendering; read when mujoco is first imported

# mujoco.mjx.warp (imported by every `mujoco.mjx`) tries the optional `warp` package (MJX's
# GPU backend, not used here) and, when it is not installed, prints these two lines to stdout
# on each import; mujoco has no setting that skips the attempt. They are dropped; anything
# else it prints (warp installed but broken, say) still shows.
_WARP_ABSENT = re.compile(r"Failed to import (warp|mujoco_warp): No module named 'warp'")


def _without_warp_absent(text: str) -> str:
    return "".join(line for line in text.splitlines(keepends=True) if not _WARP_ABSENT.fullmatch(line.rstrip("\n")))


class _QuietLoader(importlib.abc.Loader):
    def __init__(self, loader):
        self.loader = loader

    def create_module(self, spec):
        return self.loader.create_module(spec)

    def exec_module(self, module):
        printed = io.StringIO()
        try:
            with contextlib.redirect_stdout(printed):
                self.loader.exec_module(module)
        finally:
            sys.stdout.write(_without_warp_absent(printed.getvalue()))

    def __getattr__(self, name):  # get_source, get_filename, ...: the real loader's
        return getattr(self.loader, name)


class _QuietWarpImport(importlib.abc.MetaPathFinder):
    """Finds `mujoco.mjx.warp` with the other finders and runs it through `_QuietLoader`;
    leaves `sys.meta_path` once it has."""

    NAME = "mujoco.mjx.warp"

    def find_spec(self, name, path, target=None):
        if name != self.NAME:
            return None
        with contextlib.suppress(ValueError):
            sys.meta_path.remove(self)
        for finder in sys.meta_path:
            spec = finder.find_spec(name, path, target) if hasattr(finder, "find_spec") else None
            if spec is not None:
                if spec.loader is not None:
                    spec.loader = _QuietLoader(spec.loader)
                return spec
        return None


if _QuietWarpImport.NAME not in sys.modules and not any(isinstance(f, _QuietWarpImport) for f in sys.meta_path):
    sys.meta_path.insert(0, _QuietWarpImport())
