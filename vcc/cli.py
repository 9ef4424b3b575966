"""`vcc`: one command over all packages. It sits on top: nothing below imports it.

Every package's CLI module imports only argparse-level code at the top, so building the
parser starts no JAX backend; each command sets its process up (`vccjax.runtime.prepare`)
before it touches a device.
"""

from __future__ import annotations

import argparse
import sys

from argpred import cli as argpred_cli
from robot import cli as robot_cli
from search import cli as search_cli
from search import learn_cli
from vcc import bench
from vccjax import cli as vccjax_cli
from vccjax import runtime


def build_parser() -> argparse.ArgumentParser:
    p = runtime.Parser(
        prog="vcc",
        description="Visual Cognitive Computer toolkit: run cognitive programs on tabletop scenes "
                    "and induce them from examples.",
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    vccjax_cli.add_commands(sub)
    search_cli.add_commands(sub)
    learn_cli.add_commands(sub)
    argpred_cli.add_commands(sub)
    robot_cli.add_commands(sub)
    bench.add_commands(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    return runtime.run_command(build_parser(), argv)


if __name__ == "__main__":
    sys.exit(main())
