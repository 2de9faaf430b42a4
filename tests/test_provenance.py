"""A model card says how many path-traced and analytic windows the model has seen, over its chain of fine-tunes."""
from wallcli.train.provenance import seen_in_card, windows_seen


def _manifest(world, shards, **extra):
    rec = {"task": "count", "world": world, "windows_per_scene": 4, **extra}
    return {"recipe": rec, "shards": [{"n": n} for n in shards]}


def test_a_fine_tune_adds_its_windows_to_what_the_init_model_had_seen():
    old = {"training_data": {"recipe": [{"world": "mixed", "windows": 8192}], "windows": 8192}}  # a card before the field
    assert seen_in_card(old) == {"path_traced": 0, "analytic": 8192, "pt_scenes": 0}
    pt = _manifest("pt", [128, 128, 64], clean_cache={"draws": 16})
    first = windows_seen([pt, _manifest("room", [100])], old)
    assert first == {"path_traced": 320, "analytic": 8292, "pt_scenes": 5}
    # the next session's fine-tune starts from that model's card
    card = {"training_data": {"windows_seen": first}}
    assert windows_seen([_manifest("pt", [64], clean_cache={"draws": 16})], card)["path_traced"] == 384


def test_a_model_trained_from_scratch_counts_only_its_own_data():
    assert windows_seen([_manifest("room", [10, 6])], None) == {"path_traced": 0, "analytic": 16, "pt_scenes": 0}
    assert seen_in_card({}) == {"path_traced": 0, "analytic": 0, "pt_scenes": 0}
