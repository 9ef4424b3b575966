"""The `vcc` command: the emulator's commands plus induction (and, as they land, argpred, robot, bench)."""
