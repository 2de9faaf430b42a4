"""The card's trust seal: a sha256 over the fields that back its decided answers and its quoted figures.

The ONNX file's sha256 in the card ties the card to the net; nothing tied the card's own claims
(the decided/undetermined thresholds, the validation and transfer figures) to what was measured,
so a copied card with its thresholds set to 0 had every answer "decided ... right at least 97 %
of the time in validation". The seal binds those fields, and the net they were measured on (its
sha256), into one digest stored in the card's ``trust`` block. A card whose digest does not match,
or that has none, is an *unvalidated card*: it still runs, but every answer is undetermined with
that reason and ``-v`` quotes none of its figures.

This is tamper evidence, not a signature: whoever edits a card on purpose can reseal it, and by
doing so takes over the claim that the figures are measured. It catches a hand-edited or
half-copied card, which is what reaches users.

wallcli writes the seal wherever it writes a card (``wallcli train``, its calibration and
recordings steps, :func:`wallcli.infer.card.write_card`). After changing a card's figures by other
means (a research script, a re-validation), reseal it:

    python -m wallcli.infer.trust models/count.json models/activity.json
"""
from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path
from typing import Any

FORMAT = "wallcli.card-trust v1"
# The fields that decide whether an answer is relied upon, or that the commands and the report
# quote as the model's measured accuracy; and the net's sha256, so that a card's claims moved onto
# another net do not hold. Absent fields are hashed as absent (null).
FIELDS = ("sha256", "task", "classes", "fps", "window", "bins", "stride", "preprocessing",
          "confidence", "two_stage", "split", "validation", "validation_with_split", "transfer",
          "transfer_single_stage")
UNVALIDATED = "unvalidated card"


def digest(card: dict[str, Any]) -> str:
    """The sha256 of the card's trust fields, as canonical JSON (sorted keys, no spaces): the same
    for any re-indented or re-ordered copy of the card, different for any changed value."""
    fields = {k: card.get(k) for k in FIELDS}
    text = json.dumps(fields, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False)
    return hashlib.sha256(text.encode("ascii")).hexdigest()


def seal(card: dict[str, Any]) -> dict[str, Any]:
    """``card`` with its ``trust`` block set to the digest of its trust fields (in place, returned)."""
    card["trust"] = {"format": FORMAT, "fields": list(FIELDS), "sha256": digest(card),
                     "note": "sha256 of these fields as canonical JSON; a card whose fields do not match it is "
                             "an unvalidated card: every answer undetermined (wallcli/infer/trust.py)"}
    return card


def problem(card: dict[str, Any]) -> str | None:
    """None when the card's trust fields are those it was sealed with; else why it is unvalidated,
    as a reason an answer carries ('unvalidated card: ...')."""
    block = card.get("trust")
    if not isinstance(block, dict) or not isinstance(block.get("sha256"), str):
        return f"{UNVALIDATED}: it carries no trust seal, so its thresholds and figures are not known to be measured"
    if block.get("format") != FORMAT:
        return f"{UNVALIDATED}: its trust seal is of an unknown format ({str(block.get('format'))[:40]!r})"
    try:
        ok = digest(card) == block["sha256"].lower()
    except ValueError:  # a NaN or infinity in a trust field: never what training writes
        ok = False
    if not ok:
        return (f"{UNVALIDATED}: its thresholds or validation figures were changed after they were "
                "measured (they do not match the card's trust seal)")
    return None


def reseal(path: Path | str) -> str:
    """Seal the card at ``path`` in place (written atomically); returns the new digest."""
    from wallcli.errors import WallcliError
    from wallcli.io import jsonfile
    from wallcli.io.writer import write_text_atomic

    path = Path(path)
    card = jsonfile.loads(path.read_text(encoding="utf-8"))
    # (not validate_card: card.py seals through this module; a card it refuses is refused at load anyway)
    if not isinstance(card, dict) or not isinstance(card.get("sha256"), str):
        raise WallcliError(f"{path} is not a model card (no 'sha256' of its net)")
    seal(card)
    write_text_atomic(path, json.dumps(card, indent=2) + "\n", force=True)
    return card["trust"]["sha256"]


def main(argv: list[str] | None = None) -> int:
    from wallcli.errors import WallcliError

    args = sys.argv[1:] if argv is None else argv
    if not args or any(a.startswith("-") for a in args):
        print("usage: python -m wallcli.infer.trust CARD.json...  (reseal model cards after re-validating them)",
              file=sys.stderr)
        return 2
    for arg in args:
        try:
            print(f"{arg}: trust sha256 {reseal(arg)}", file=sys.stderr)
        except (OSError, ValueError, WallcliError) as exc:
            print(f"Error: {arg}: {' '.join(str(exc).split())}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
