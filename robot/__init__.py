"""A simulated arm (MuJoCo, batched on MJX) that carries out VCC programs from a camera image."""

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # offscreen rendering; read when mujoco is first imported
