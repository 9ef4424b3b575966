"""`vcc argpred` commands refuse bad options and corrupt weights in one error line,
writing nothing."""

from __future__ import annotations

import json

from tests.argpred.shipped_copy import copy_shipped


def _one_error_line(capsys, fragment: str) -> None:
    err = capsys.readouterr().err
    assert err.startswith("vcc") and ": error: " in err and err.count("\n") == 1 and fragment in err, err


def test_argpred_commands_refuse_bad_options_in_one_line_writing_nothing(tmp_path, capsys, monkeypatch):
    from argpred import cli as argcli
    from vcc.cli import main

    monkeypatch.setattr(argcli, "DEFAULT_DATA", tmp_path / "default-data")  # where train would draw its data
    w, d, res = tmp_path / "new.msgpack", tmp_path / "data", tmp_path / "r.json"
    train = ["argpred", "train", "--out", str(w), "--quiet"]
    for argv, fragment in [
        (train + ["--epochs", "0"], "argument --epochs: 0 is out of range"),
        (train + ["--lr", "nan"], "argument --lr: nan is not a finite number"),
        (train + ["--lr", "-0.1"], "argument --lr: -0.1 is out of range"),
        (train + ["--positive-weight", "inf"], "argument --positive-weight: inf is not a finite number"),
        (train + ["--l1", "-1"], "argument --l1: -1 is out of range"),
        (train + ["--members", "0"], "argument --members: 0 is out of range"),
        (train + ["--batch", "0"], "argument --batch: 0 is out of range"),
        (train + ["--programs", "0"], "argument --programs: 0 is out of range"),
        (train + ["--joined", "1.5"], "argument --joined: 1.5 is out of range"),
        (train + ["--carry", "-1"], "argument --carry: -1 is out of range"),
        (train + ["--loops", "-1"], "argument --loops: -1 is out of range"),
        (train + ["--pool", "everywhere"], "argument --pool: invalid choice"),
        (train + ["--pool", "hidden", "--hidden", "0"], "--pool hidden pools the hidden channels"),
        (["argpred", "train", "--out", str(tmp_path), "--quiet"], "write .msgpack"),
        (["argpred", "data", "--out", str(d), "--programs", "0"], "argument --programs: 0 is out of range"),
        (["argpred", "data", "--out", str(d), "--joined", "nan"], "argument --joined: nan is not a finite number"),
        (["argpred", "eval", "--concepts", "", "--out", str(res)], "has an empty name"),
        (["argpred", "eval", "--concepts", "no_such", "--out", str(res)], "unknown concept(s): no_such"),
        (["argpred", "eval", "--show", "-1", "--out", str(res)], "argument --show: -1 is out of range"),
        (["argpred", "eval", "--record", "--concepts", "remove_bottom_obj"], "--record keeps the weights' own recall"),
        (["argpred", "eval", "--record", "--threshold", "0.6"], "--record keeps the weights' own recall"),
        (["argpred", "eval", "--record", "--fill", "gained"], "--record keeps the weights' own recall"),
        (["argpred", "eval", "--fill", "both", "--out", str(res)], "argument --fill: invalid choice"),
        (["argpred", "eval", "--record", "--filters", "acted"], "--record keeps the weights' own recall"),
        (["argpred", "eval", "--filters", "both", "--out", str(res)], "argument --filters: invalid choice"),
        (["argpred", "eval", "--threshold", "0", "--out", str(res)], "argument --threshold: 0 is out of range"),
        (["argpred", "data", "--out", str(d), "--kind", "loops"], "argument --kind: invalid choice"),
        (["argpred", "eval", "--weights", str(tmp_path / "none.msgpack"), "--out", str(res)], "none.msgpack: missing"),
    ]:
        assert main(argv) == 2, argv
        _one_error_line(capsys, fragment)
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing drawn, trained or written
    # corrupt weights: refused, and --record leaves the card as it was
    copy = copy_shipped(tmp_path)
    data = bytearray(copy.read_bytes())
    data[len(data) // 3] ^= 0x01
    copy.write_bytes(bytes(data))
    card = copy.with_suffix(".json").read_bytes()
    good = json.loads(card)
    assert main(["argpred", "eval", "--weights", str(copy), "--record", "--out", str(res)]) == 2
    _one_error_line(capsys, "sha256 differs from its card")
    assert copy.with_suffix(".json").read_bytes() == card
    copy.with_suffix(".json").write_text("{cut")
    assert main(["argpred", "eval", "--weights", str(copy), "--out", str(res)]) == 2
    _one_error_line(capsys, "w.json: not JSON")
    import hashlib

    import msgpack

    for body in (msgpack.packb(5), msgpack.packb([1, 2]), b""):  # the card's sha256 matches, the content is not weights
        copy.write_bytes(body)
        copy.with_suffix(".json").write_text(json.dumps({**good, "sha256": hashlib.sha256(body).hexdigest()}))
        assert main(["argpred", "eval", "--weights", str(copy), "--out", str(res)]) == 2
        _one_error_line(capsys, "does not hold this model's weights")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w.json", "w.msgpack"]
