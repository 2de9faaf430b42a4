"""How many path-traced and analytic windows a model has learnt from, over its whole chain of
fine-tunes (issue 35: each session adds path-traced scenes and fine-tunes the shipped model, and
its card says what it has seen).

Counted are the distinct windows of the training datasets (each clean path-traced scene gives
several windows under fresh cameras: ``pt_scenes`` counts the scenes; an activity net trained on a
count dataset skips its two-person windows, counted all the same), added to what the --init
model had seen. A card from before this field is read from its training_data recipes.
"""

from __future__ import annotations


def _from_recipes(recipes: list, windows: list) -> dict:
    seen = {"path_traced": 0, "analytic": 0, "pt_scenes": 0}
    for rec, n in zip(recipes, windows):
        rec = rec or {}
        if rec.get("world") == "pt":
            seen["path_traced"] += int(n)
            draws = int((rec.get("clean_cache") or {}).get("draws", 1))
            seen["pt_scenes"] += -(-int(n) // (int(rec.get("windows_per_scene", 4)) * draws))
        else:
            seen["analytic"] += int(n)
    return seen


def seen_in_card(card: dict) -> dict:
    """The card's windows_seen, or what its training_data implies (older cards)."""
    td = card.get("training_data") or {}
    if isinstance(td.get("windows_seen"), dict):
        return dict(td["windows_seen"])
    recipes = td.get("recipe") or []
    if not recipes:
        return {"path_traced": 0, "analytic": 0, "pt_scenes": 0}
    windows = [r.get("windows", 0) if isinstance(r, dict) else 0 for r in recipes]
    if len(recipes) == 1 and td.get("windows"):
        windows = [td["windows"]]
    return _from_recipes(recipes, windows)


def windows_seen(manifests: list, init_card: dict | None) -> dict:
    """This run's datasets (their manifests) plus what the --init model had seen."""
    mine = _from_recipes([m.get("recipe") for m in manifests],
                         [sum(int(s["n"]) for s in m.get("shards", [])) for m in manifests])
    base = seen_in_card(init_card) if init_card else {"path_traced": 0, "analytic": 0, "pt_scenes": 0}
    return {k: int(base.get(k, 0)) + int(mine.get(k, 0)) for k in ("path_traced", "analytic", "pt_scenes")}
