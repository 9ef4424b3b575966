"""Training the argument CNN with optax: Adam on the mean binary cross-entropy of the
labels plus an L1 penalty on the convolution kernels (the paper's regulariser).

Seeded throughout (initialisation, the validation split, each epoch's order), and
checkpointed after every epoch (msgpack: epoch, parameters, optimiser state), so an
interrupted run resumes and ends with the same weights as an uninterrupted one (and a
finished run can be continued for more epochs).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import optax
from flax import serialization

from argpred.features import features_from_cells
from argpred.model import ArgNet
from argpred.predict import THRESHOLD
from argpred.weights import init_params
from vccjax import files


@dataclasses.dataclass(frozen=True)
class TrainSettings:
    hidden: int = 32
    kernel: int = 3
    depth: int = 1
    evidence: str = "relu"  # or "signed" (the paper's plain sum) or "shown" (argpred.model)
    bias_start: float = -4.0
    pool: str = "labels"  # or "hidden" (argpred.model)
    epochs: int = 30
    batch: int = 64
    learning_rate: float = 3e-3
    l1: float = 1e-4  # on the sum of |kernel weights|
    positive_weight: float = 16.0  # > 1 trades extra arguments for recall (a missed one loses the concept)
    validation: float = 0.1  # share of programs held out
    seed: int = 0


def model_of(settings: TrainSettings) -> ArgNet:
    return ArgNet(hidden=settings.hidden, kernel=settings.kernel, depth=settings.depth, evidence=settings.evidence,
                  bias_start=settings.bias_start, pool=settings.pool)


def _l1(params) -> jax.Array:
    return sum(jnp.abs(w).sum() for path, w in jax.tree_util.tree_leaves_with_path(params)
               if "kernel" in jax.tree_util.keystr(path))


@functools.partial(jax.jit, static_argnums=(0, 1))
def _step(model: ArgNet, tx: optax.GradientTransformation, l1: float, pos: float, params, opt_state, x, y):
    def loss_fn(p):
        logits = model.apply({"params": p}, x, jnp.ones(x.shape[:2]))
        bce = optax.sigmoid_binary_cross_entropy(logits, y)
        weighted = (bce * jnp.where(y > 0.5, pos, 1.0)).mean()
        return weighted + l1 * _l1(p), (bce.mean(), weighted)

    (_, (bce, weighted)), grads = jax.value_and_grad(loss_fn, has_aux=True)(params)
    updates, opt_state = tx.update(grads, opt_state, params)
    return optax.apply_updates(params, updates), opt_state, bce, weighted


@functools.partial(jax.jit, static_argnums=0)
def _held_out(model: ArgNet, params, x, y):
    logits = model.apply({"params": params}, x, jnp.ones(x.shape[:2]))
    return optax.sigmoid_binary_cross_entropy(logits, y).mean(), jax.nn.sigmoid(logits)


def split(n: int, settings: TrainSettings) -> tuple[np.ndarray, np.ndarray]:
    order = np.random.default_rng([settings.seed, 1]).permutation(n)
    k = int(round(n * settings.validation))
    return np.sort(order[k:]), np.sort(order[:k])


def batches(data: dict, idx: np.ndarray, size: int):
    for s in range(0, len(idx), size):
        b = idx[s : s + size]
        yield features_from_cells(data["inputs"][b], data["outputs"][b]), data["labels"][b].astype(np.float32)


def train(data: dict, settings: TrainSettings, checkpoint: str | Path | None = None,
          progress: bool = True, log: Callable[[str], None] = print) -> tuple[ArgNet, dict, list[dict]]:
    """Train on `data` (argpred.data.load); returns (model, params, per-epoch history)."""
    from tqdm import tqdm

    model = model_of(settings)
    tx = optax.adam(settings.learning_rate)
    params = init_params(model, settings.seed)
    opt_state = tx.init(params)
    history: list[dict] = []
    start = 0
    ckpt = Path(checkpoint) if checkpoint else None
    if ckpt and ckpt.exists():
        try:
            state = serialization.msgpack_restore(ckpt.read_bytes())
            if state.get("settings") != _settings_dict(settings):
                raise ValueError(f"{ckpt}: a checkpoint of other settings; remove it or use the same ones")
            if state.get("data") != data_fingerprint(data):
                raise ValueError(f"{ckpt}: a checkpoint trained on other data; remove it or use the same data")
            params = serialization.from_state_dict(params, state["params"])
            opt_state = serialization.from_state_dict(opt_state, state["opt_state"])
        except (KeyError, TypeError, AttributeError) as e:
            raise ValueError(f"{ckpt}: not a checkpoint of this model ({e}); remove it") from None
        start = int(state["epoch"])
        history = [state["history"][k] for k in sorted(state["history"], key=int)]
        log(f"resuming after epoch {start}")
    tr, va = split(len(data["labels"]), settings)
    bar = tqdm(range(start, settings.epochs), desc="argpred train", unit="epoch", disable=not progress)
    for epoch in bar:
        order = tr[np.random.default_rng([settings.seed, 2, epoch]).permutation(len(tr))]
        losses, objective = [], []
        for x, y in batches(data, order, settings.batch):
            params, opt_state, bce, weighted = _step(model, tx, settings.l1, settings.positive_weight,
                                                     params, opt_state, jnp.asarray(x), jnp.asarray(y))
            losses.append(float(bce))
            objective.append(float(weighted))
            if not math.isfinite(objective[-1]):  # diverged: nothing of it is kept or written
                raise ValueError(f"training diverged at epoch {epoch + 1} (the loss is {objective[-1]}); "
                                 "lower --lr or change the settings")
        val = evaluate(model, params, data, va, settings.batch) if len(va) else {}
        # train_loss: what Adam lowers (used labels weighted); train_bce: the plain mean
        history.append({"epoch": epoch + 1, "train_loss": float(np.mean(objective)),
                        "train_bce": float(np.mean(losses)), **val})
        bar.set_postfix(train=f"{history[-1]['train_bce']:.4f}", val=f"{val.get('val_bce', float('nan')):.4f}")
        if ckpt:
            files.write_whole(ckpt, serialization.to_bytes({
                "epoch": epoch + 1, "params": params, "opt_state": opt_state,
                "history": {str(k): h for k, h in enumerate(history)}, "settings": _settings_dict(settings),
                "data": data_fingerprint(data)}))
    return model, params, history


def train_members(data: dict, settings: TrainSettings, members: int, checkpoint: str | Path | None = None,
                  workers: int = 1, progress: bool = True) -> tuple[ArgNet, dict, list[list[dict]]]:
    """An ensemble: `members` networks trained alike from seeds seed, seed+1, ...
    (`workers` at a time, each in its own process and checkpoint, so an interrupted
    run resumes every member); returns (model, stacked params, each member's history).
    One member is plain `train`."""
    from argpred.weights import stack

    if members < 1:
        raise ValueError(f"an ensemble of {members} members")
    if members == 1:
        model, params, history = train(data, settings, checkpoint, progress)
        return model, params, [history]
    ckpt = Path(checkpoint) if checkpoint else None
    jobs = [(data, dataclasses.replace(settings, seed=settings.seed + k),
             ckpt.with_suffix(f".m{k}.ckpt") if ckpt else None) for k in range(members)]
    if workers > 1:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        from tqdm import tqdm

        with ProcessPoolExecutor(min(workers, members), mp_context=multiprocessing.get_context("spawn")) as pool:
            done = list(tqdm(pool.map(_member, jobs), total=members, desc="argpred members", disable=not progress))
    else:
        done = [_member(job, progress) for job in jobs]
    return model_of(settings), stack([p for p, _ in done]), [h for _, h in done]


def _member(job, progress: bool = False):
    data, settings, ckpt = job
    _, params, history = train(data, settings, ckpt, progress=progress, log=lambda s: None)
    return jax.device_get(params), history


def data_fingerprint(data: dict) -> str:
    """sha256 of the training programs and labels: a checkpoint resumes only on the data it
    was trained on (a folder grown from 1,000 to 3,000 programs is other data)."""
    import hashlib

    h = hashlib.sha256("\n".join(map(str, data["programs"])).encode())
    h.update(np.ascontiguousarray(data["labels"]).tobytes())
    return h.hexdigest()


def _settings_dict(settings: TrainSettings) -> dict:
    """What a checkpoint must share with the run resuming it (more epochs may follow)."""
    return {k: str(v) for k, v in dataclasses.asdict(settings).items() if k != "epochs"}


def evaluate(model: ArgNet, params, data: dict, idx: np.ndarray, batch: int = 256) -> dict:
    """Held-out BCE, and the share of programs whose labels are all right at the threshold."""
    total, right, n = 0.0, 0, 0
    for x, y in batches(data, idx, batch):
        bce, p = _held_out(model, params, jnp.asarray(x), jnp.asarray(y))
        total += float(bce) * len(y)
        right += int(np.all((np.asarray(p) >= THRESHOLD) == (y > 0.5), axis=1).sum())
        n += len(y)
    return {"val_bce": total / n, "val_all_labels_right": right / n}
