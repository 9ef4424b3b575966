"""Hostile cases for `vcc argpred data` / `train` / `eval`."""

from __future__ import annotations

from tests.vcc.hostile_table import NO_DEVICE, _flags, case

# ---- vcc argpred data / train / eval ---------------------------------------------------------
AD = {"out": "{tmp}/ad", "programs": "1", "quiet": True}
W_AD = ["{tmp}/ad"]
case("ap-data-programs-zero", "argpred", "data", *_flags(AD, programs="0"), writes=W_AD)
case("ap-data-programs-negative", "argpred", "data", *_flags(AD, programs="-3"), writes=W_AD)
case("ap-data-programs-text", "argpred", "data", *_flags(AD, programs="ten"), writes=W_AD)
case("ap-data-joined-negative", "argpred", "data", *_flags(AD, joined="-0.1"), writes=W_AD)
case("ap-data-joined-over", "argpred", "data", *_flags(AD, joined="1.5"), writes=W_AD)
case("ap-data-joined-nan", "argpred", "data", *_flags(AD, joined="nan"), writes=W_AD)
case("ap-data-joined-inf", "argpred", "data", *_flags(AD, joined="inf"), writes=W_AD)
case("ap-data-workers-negative", "argpred", "data", *_flags(AD, workers="-1"), writes=W_AD)
case("ap-data-kind-bad", "argpred", "data", *_flags(AD, kind="painted"), writes=W_AD)
case("ap-data-seed-negative", "argpred", "data", *_flags(AD, seed="-1"), writes=W_AD, slow=True)
case("ap-data-out-missing", "argpred", "data", *_flags(AD, out=None))
case("ap-data-out-file", "argpred", "data", *_flags(AD, out="{file}"), writes=["{file}"])
case("ap-data-out-ro", "argpred", "data", *_flags(AD, out="{ro}"))
case("ap-data-out-full", "argpred", "data", *_flags(AD, out="{full}"))
case("ap-data-out-empty", "argpred", "data", *_flags(AD, out=""))
case("ap-data-out-parent-file", "argpred", "data", *_flags(AD, out="{file}/ad"), writes=["{file}"])
# train: one program, one epoch, one member, no carry programs; JAX cannot start (NO_DEVICE), so that a
# missing check ends in a crash the case reports instead of in training
AT = {"out": "{tmp}/w.msgpack", "data": "{tmp}/ad", "programs": "1", "epochs": "1", "members": "1", "carry": "0",
      "quiet": True}
W_AT = ["{tmp}/w.msgpack", "{tmp}/w.json", "{tmp}/w.ckpt"]
for cid, over in [
    ("epochs-zero", {"epochs": "0"}), ("batch-zero", {"batch": "0"}), ("kernel-zero", {"kernel": "0"}),
    ("depth-zero", {"depth": "0"}), ("members-zero", {"members": "0"}), ("hidden-negative", {"hidden": "-1"}),
    ("carry-negative", {"carry": "-1"}), ("workers-negative", {"workers": "-1"}), ("programs-zero", {"programs": "0"}),
    ("joined-over", {"joined": "2"}), ("lr-zero", {"lr": "0"}), ("lr-negative", {"lr": "-0.1"}),
    ("lr-nan", {"lr": "nan"}), ("lr-inf", {"lr": "inf"}), ("pw-zero", {"positive_weight": "0"}),
    ("pw-nan", {"positive_weight": "nan"}), ("l1-negative", {"l1": "-1"}), ("l1-nan", {"l1": "nan"}),
    ("bias-nan", {"bias_start": "nan"}), ("bias-inf", {"bias_start": "-inf"}), ("evidence-bad", {"evidence": "vibes"}),
    ("epochs-text", {"epochs": "thirty"}), ("hidden-huge", {"hidden": "1000000000"}),
    ("kernel-huge", {"kernel": "1000000000"}), ("members-huge", {"members": "1000000000"}),
    ("out-dir", {"out": "{tmp}/dir.msgpack"}), ("out-ro", {"out": "{ro}.msgpack"}),
    ("out-parent-file", {"out": "{file}/w.msgpack"}), ("out-empty", {"out": ""}),
    ("data-two-missing", {"data": "{tmp}/nodata1,{tmp}/nodata2"}), ("data-file", {"data": "{file},{dir}"}),
]:
    case(f"ap-train-{cid}", "argpred", "train", *_flags(AT, **over), writes=W_AT + ["{tmp}/ad"], env=NO_DEVICE)
AE = {"concepts": "remove_top_obj"}
for name in ("garbage", "msgpack_int", "flipped", "huge_hidden", "zero_kernel", "members_str", "card_list",
             "no_card"):
    case(f"ap-eval-weights-{name.replace('_', '-')}", "argpred", "eval",
         *_flags(AE, weights=f"{{tmp}}/w/{name}.msgpack"), setup="weights",
         slow=name in ("huge_hidden", "huge_kernel", "negative_hidden", "zero_kernel"))
case("ap-eval-weights-missing", "argpred", "eval", *_flags(AE, weights="{missing}"))
case("ap-eval-weights-plain-file", "argpred", "eval", *_flags(AE, weights="{file}"))
case("ap-eval-concepts-empty", "argpred", "eval", *_flags(AE, concepts=""))
case("ap-eval-concepts-unknown", "argpred", "eval", *_flags(AE, concepts="bogus"))
for name in ("flipped", "nan_coords", "shape_index"):
    case(f"ap-eval-dataset-{name.replace('_', '-')}", "argpred", "eval", *_flags(AE, dataset=f"{{tmp}}/ds/{name}"),
         setup="ds", slow=True)
case("ap-eval-dataset-missing", "argpred", "eval", *_flags(AE, dataset="{missing}"))
case("ap-eval-out-ro", "argpred", "eval", *_flags(AE, out="{ro}.json"), slow=True)
case("ap-eval-out-dir", "argpred", "eval", *_flags(AE, out="{tmp}/dir.json"), writes=["{tmp}/dir.json"], slow=True)
case("ap-eval-out-parent-file", "argpred", "eval", *_flags(AE, out="{file}/r.json"), writes=["{file}"], slow=True)
case("ap-eval-record-concepts", "argpred", "eval", *_flags(AE, record=True))
case("ap-eval-show-negative", "argpred", "eval", *_flags(AE, show="-1"))
case("ap-eval-show-text", "argpred", "eval", *_flags(AE, show="all"))
