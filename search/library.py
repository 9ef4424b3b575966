"""The learned library: what explore-compress learned on the 546 concepts, kept so a new
concept is searched with it instead of from a uniform start (learning to learn).

It is the order-1 model and the subroutines fitted on every program a finished run found
(not the model its last iteration searched with), stored as the subroutines' bodies and
the sparse transition counts (integers), so loading refits exactly the model that was
built. A card names the source run, its settings, the concepts it found and the sha256
of its results file; the argument predictor the library is used with is named by the
sha256 of its weights. The file holds the sha256 of its own content: loading refuses an
edited or foreign file, a library of another format version, and one made for other
predictor weights.
"""

from __future__ import annotations

import dataclasses
import hashlib
from importlib import resources
from pathlib import Path

import numpy as np

from search.model import MarkovModel, Vocabulary, transition_counts
from vccjax.errors import DataFileError, read_json
from vccjax.records import check_fields
from vccjax.sealed import intact, seal, write_whole

FORMAT = "vccjax-library"
VERSION = 1


@dataclasses.dataclass(frozen=True)
class Library:
    """A vocabulary (atoms and subroutines), the Markov model over it, and its card."""

    vocab: Vocabulary
    model: MarkovModel
    card: dict
    sha256: str  # of the content, as the file records it

    @property
    def short(self) -> str:
        return self.sha256[:12]


def shipped_library() -> Path:
    """The library built from the run of record (`vcc library build`), in the package."""
    return Path(str(resources.files("search").joinpath("data/library.json")))


def fit(programs: list[tuple[int, ...]], order: int, epsilon: float, max_subroutines: int,
        subroutines: bool = True) -> tuple[Vocabulary, np.ndarray]:
    """Compress atomic programs (greedy MAP, `search.compress`) and count the transitions
    of the compressed programs and the subroutines' bodies: what the model is fitted on."""
    from search.compress import compress

    seqs = [list(p) for p in programs]
    vocab = Vocabulary()
    if subroutines and seqs:
        seqs, vocab, _ = compress(seqs, vocab, order=order, epsilon=epsilon, cap=max_subroutines)
    return vocab, transition_counts(seqs + [list(b) for b in vocab.bodies], vocab.size)


def build(run_folder: str | Path) -> dict:
    """The library file's content for a finished induction run (its `run.json` and
    `results.jsonl`): every program it found, compressed, and the model fitted on them."""
    from argpred.weights import load as load_weights
    from search.induce import Run
    from vccjax.machine.program import parse

    folder = Path(run_folder)
    meta_path = folder / "run.json"
    meta = read_json(meta_path, DataFileError, "missing (not an induction run folder)")
    try:
        settings = meta["settings"]
        order, epsilon, cap = int(settings["order"]), float(settings["epsilon"]), int(settings["max_subroutines"])
        _check_model_numbers(order, epsilon)
    except (KeyError, TypeError, ValueError) as e:
        raise DataFileError(f"{meta_path}: not an induction run's settings ({e})") from None
    found = Run.view(folder).found()
    if not found:
        raise DataFileError(f"{folder / 'results.jsonl'}: the run found no program to learn from")
    programs = [parse(found[c]["program"]).ops for c in sorted(found)]
    vocab, counts = fit(programs, order, epsilon, cap, settings.get("subroutines", True))
    rows, cols = np.nonzero(counts)
    card = {
        "source_run": folder.name, "settings": settings, "concepts": sorted(found),
        "results_sha256": hashlib.sha256((folder / "results.jsonl").read_bytes()).hexdigest(),
        "predictor_sha256": load_weights()[2]["sha256"],
    }
    return seal({
        "format": FORMAT, "version": VERSION, "order": order, "epsilon": epsilon,
        "subroutines": vocab.to_json(),
        "transitions": [[int(i), int(j), int(counts[i, j])] for i, j in zip(rows, cols, strict=True)],
        "card": card,
    })


def save(content: dict, path: str | Path) -> str:
    """Write a library file whole (a temporary file replaced); returns its content sha256."""
    write_whole(Path(path), content)
    return content["content_sha256"]


def _check_model_numbers(order: int, epsilon: float) -> None:
    if order not in (0, 1):
        raise ValueError(f"order {order}: 0 or 1")
    if not 0 <= epsilon <= 1:  # NaN fails this too
        raise ValueError(f"epsilon {epsilon}: from 0 to 1")


def load(path: str | Path | None = None, check_predictor: bool = True) -> Library:
    """The library at `path` (default: the shipped one), verified."""
    path = Path(path) if path is not None else shipped_library()
    content = read_json(path, DataFileError, "missing")
    if not isinstance(content, dict) or content.get("format") != FORMAT:
        raise DataFileError(f"{path}: not a {FORMAT} file")
    if content.get("version") != VERSION:
        raise DataFileError(f"{path}: library format version {content.get('version')}, this vccjax reads {VERSION} "
                            "(rebuild it with `vcc library build`)")
    if not intact(content):
        raise DataFileError(f"{path}: content sha256 mismatch (edited or corrupt)")
    try:
        vocab = Vocabulary.from_json(content["subroutines"])
        order, epsilon = int(content["order"]), float(content["epsilon"])
        counts = np.zeros((vocab.size + 1, vocab.size + 1))
        _check_model_numbers(order, epsilon)
        for i, j, n in content["transitions"]:
            if not (isinstance(n, int) and n >= 0 and 0 <= i <= vocab.size and 0 <= j <= vocab.size):
                raise ValueError(f"transition {[i, j, n]}: counts are whole numbers of at least 0 between tokens")
            counts[i, j] = n
        card = check_fields(content["card"], {"settings": (dict,), "concepts": (list,)}, f"{path}: card")
    except (KeyError, TypeError, ValueError, IndexError) as e:
        raise DataFileError(f"{path}: malformed library ({e})") from None
    if check_predictor:
        from argpred.weights import load as load_weights

        mine = load_weights()[2]["sha256"]
        if card.get("predictor_sha256") != mine:
            raise DataFileError(f"{path}: made for other argument-predictor weights "
                                f"({str(card.get('predictor_sha256'))[:12]}..., these are {mine[:12]}...); "
                                "rebuild it with `vcc library build`")
    return Library(vocab, MarkovModel.from_counts(counts, order, epsilon), card, content["content_sha256"])
