"""`vcc`: one command over all packages. It sits on top: nothing below imports it."""

from __future__ import annotations

import argparse
import sys

if len(sys.argv) > 1 and sys.argv[1] == "robot":  # MJX's XLA settings must precede JAX's start,
    from robot.cli import prepare_process  # which importing vccjax triggers

    prepare_process(sys.argv[2:])

from argpred import cli as argpred_cli  # noqa: E402
from robot import cli as robot_cli  # noqa: E402
from search import cli as search_cli  # noqa: E402
from vcc import bench  # noqa: E402
from vccjax import cli as vccjax_cli  # noqa: E402


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="vcc",
        description="Visual Cognitive Computer toolkit: run cognitive programs on tabletop scenes "
                    "and induce them from examples.",
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    vccjax_cli.add_commands(sub)
    search_cli.add_commands(sub)
    argpred_cli.add_commands(sub)
    robot_cli.add_commands(sub)
    bench.add_commands(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    return vccjax_cli.main(argv, build_parser())


if __name__ == "__main__":
    sys.exit(main())
