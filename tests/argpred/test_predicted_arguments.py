"""Which predicted arguments pass (threshold, gained fill colours, filters the acted-on
objects rule out), and the search inducing with them."""

from __future__ import annotations

import json

import numpy as np

from argpred.predict import THRESHOLD, argument_logp


def test_predicted_arguments_keep_only_those_that_pass():
    probs = {"set_color_attn": np.array([0.9, 0.6, 0.2, 0.1]), "fill_color": np.array([0.1, 0.2, 0.3, 0.54]),
             "set_shape_attn": np.array([0.55, 0.0, 0.0, 0.0, 0.0])}
    lp = argument_logp(probs)
    assert np.isclose(np.exp(lp["set_color_attn"][:2]).sum(), 1) and np.isinf(lp["set_color_attn"][2:]).all()
    assert lp["set_color_attn"][0] > lp["set_color_attn"][1]
    assert np.isinf(lp["fill_color"]).all()  # nothing passes: the instruction is left out
    assert lp["set_shape_attn"][0] == 0 and THRESHOLD == 0.55
    higher = argument_logp(probs, threshold=0.6)  # a higher threshold: set_shape_attn left out, green kept
    assert np.isinf(higher["set_shape_attn"]).all() and np.isfinite(higher["set_color_attn"][:2]).all()
    assert np.isclose(np.exp(higher["set_color_attn"][:2]).sum(), 1)


def test_a_higher_threshold_passes_fewer_arguments(tmp_path):
    """Recall and extra arguments at two thresholds, on a few concepts: every argument
    passing 0.6 passes 0.55, so 0.6 recalls no concept 0.55 misses and passes no more
    extra arguments; the result file says which threshold it measured."""
    from vcc.cli import main

    concepts = "change_all_objs_color,move_all_objs_down,change_red_objs_color,remove_bottom_obj,move_to_top_edge"
    runs = {}
    for t in ("0.55", "0.6"):
        out = tmp_path / f"r{t}.json"
        assert main(["argpred", "eval", "--concepts", concepts, "--threshold", t, "--out", str(out), "--show", "0"]) == 0
        runs[t] = json.loads(out.read_text())
        assert runs[t]["threshold"] == float(t) and ("--threshold" in runs[t]["command"]) == (t != "0.55")
    low, high = runs["0.55"], runs["0.6"]
    assert set(low["missed"]) <= set(high["missed"]) and high["recalled"] <= low["recalled"]
    assert all(high["mean_extra_arguments"][f] <= v for f, v in low["mean_extra_arguments"].items())


def test_fill_arguments_from_the_gained_colours_recall_the_fills_and_pass_no_extra_one(tmp_path):
    """`--fill gained` (what the search takes by default): every fill_color argument a
    reference program uses is recalled and none it does not use passes; the filters are
    the network's either way."""
    from vcc.cli import main

    concepts = ("change_all_objs_color,move_all_objs_down,change_red_objs_color,remove_bottom_obj,"
                "move_right_most_obj_to_top_edge_AND_change_color")
    runs = {}
    for fill in ("predicted", "gained"):
        out = tmp_path / f"{fill}.json"
        assert main(["argpred", "eval", "--concepts", concepts, "--fill", fill, "--out", str(out), "--show", "0"]) == 0
        runs[fill] = json.loads(out.read_text())
        assert runs[fill]["fill"] == fill and ("--fill" in runs[fill]["command"]) == (fill == "gained")
    gained, network = runs["gained"], runs["predicted"]
    assert gained["mean_extra_arguments"]["fill_color"] == 0
    assert not any("fill_color" in miss for miss in gained["missed"].values())
    for f in ("set_shape_attn", "set_color_attn"):
        assert gained["mean_extra_arguments"][f] == network["mean_extra_arguments"][f]


def test_filters_the_objects_acted_on_rule_out_drop_extra_filters_and_no_used_one(tmp_path):
    """`--filters acted` (what the search takes by default) on concepts that act on every
    object and on filtered ones: the loops lose the filters the network passes them,
    and no concept loses a filter value its program uses."""
    from vcc.cli import main

    concepts = "change_all_objs_color,move_all_objs_down,change_red_objs_color,move_all_yellow_left"
    runs = {}
    for filters in ("network", "acted"):
        out = tmp_path / f"{filters}.json"
        assert main(["argpred", "eval", "--concepts", concepts, "--fill", "gained", "--filters", filters,
                     "--out", str(out), "--show", "0"]) == 0
        runs[filters] = json.loads(out.read_text())
        assert runs[filters]["filters"] == filters and ("--filters" in runs[filters]["command"]) == (filters == "acted")
    acted, network = runs["acted"], runs["network"]
    assert acted["recalled"] == network["recalled"]
    for c in ("change_all_objs_color", "move_all_objs_down"):
        assert c in network["extra_arguments"] and c not in acted["extra_arguments"]
    assert sum(acted["mean_extra_arguments"][f] for f in ("set_shape_attn", "set_color_attn")) < \
        sum(network["mean_extra_arguments"][f] for f in ("set_shape_attn", "set_color_attn"))


def test_induce_with_predicted_arguments(tmp_path, capsys, monkeypatch):
    from vcc.cli import main

    monkeypatch.setenv("VCCJAX_CACHE", "off")
    out = tmp_path / "pred"
    argv = ["induce", "--concepts", "change_target_obj_to_given_color,remove_bottom_obj", "--out", str(out),
            "--budget", "20000", "--iterations", "1", "--args", "predicted+fixation", "--quiet"]
    assert main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["found"] == 2 and summary["exact_on_all_test_pairs"] == 2
