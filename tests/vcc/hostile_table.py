"""The hostile-input table's format and what fills it: `case` appends to `CASES`, which
the themed `hostile_cases_*` modules fill and `hostile_cases.py` puts together.

Each case: {"id", "argv", optional "setup" (a name or list of names of the runner's
SETUPS), optional "writes" (output paths that must be left absent or as they were),
optional "env" (extra environment), optional "slow"}. Every case must fail: non-zero
exit, no traceback, exactly one line on stderr, within the timeout, nothing half-written.

Templates in argv, writes and env (the runner's `templates`):
  {tmp}      the case's own folder (also the cwd; HOME is {tmp}/home, VCC_LIBRARY {tmp}/library)
  {file}     an existing regular file          {dir}    an existing empty folder
  {empty}    an empty file                     {bin}    a file of random bytes
  {missing}  a path that does not exist        {full}   /dev/full
  {ro}       a path that cannot be created (under /proc); {ro_dir} its parent
  {shipped}  the shipped dataset folder        {repo}   the repository
Every case folder also holds dir.<ext> (a folder where a file is meant) for ext in png,
gif, json, mp4, jpg, msgpack. {full} is given only where a folder is meant: given as a
file to write, an atomic writer running as root would rename its temporary file over
the device node.
Setups (files under {tmp}): scenes -> s/*.json; images -> img/*; progs -> p/*.vcc and
p/list_*.txt (`name: program` lines); fifo -> fifo.{json,txt,vcc,png} (named pipes: a
read blocks); ds -> ds/<variant> (one-concept datasets, each corrupt in one way);
runs -> runs/<variant> (induce run folders) and runs/models/*.json (model-K.json);
libs -> lib/*.json (library files); weights -> w/*.msgpack (+ .json cards);
saved, saved_noarm -> the user's saved concepts; examples -> ex/<variant> (vcc learn
pairs); suite -> suite/ (a robot suite folder); bench -> b/* (what bench report reads).

Cheap settings keep a case from doing real work should a check be missing: induce
and learn cases search one concept with a budget of 1 or 2000 on uniform models;
argpred train draws one program for one epoch; robot run/suite/stress and argpred
train cases run with JAX unable to start (NO_DEVICE), so a missing check ends in a
crash the case reports, never in training or rollouts. A few cases whose bad input
would otherwise start long work carry a second fault that stops it (said where).
"""

from __future__ import annotations

# JAX cannot start: no training, no rollout (the argpred train and robot cases)
NO_DEVICE = {"JAX_PLATFORMS": "hostile-no-device"}


def _flags(defaults: dict, **over) -> list[str]:
    """Command-line flags from `defaults` with `over` replacing (None drops one)."""
    merged = {**defaults, **over}
    argv: list[str] = []
    for k, v in merged.items():
        if v is None or v is False:
            continue
        flag = "--" + k.rstrip("_").replace("_", "-")
        argv += [flag] if v is True else [flag, str(v)]
    return argv


CASES: list[dict] = []


def case(id: str, *argv: str, setup=None, writes=None, slow: bool = False, env=None) -> None:
    c: dict = {"id": id, "argv": list(argv)}
    if setup:
        c["setup"] = setup
    if writes:
        c["writes"] = list(writes)
    if slow:
        c["slow"] = True
    if env:
        c["env"] = env
    CASES.append(c)
