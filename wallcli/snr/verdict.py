"""What ``wallcli snr``'s figures say, in one line: is there a wall signal above the noise, and at
which block size.

The 1x1 row alone cannot say: a codec's slow residue and a sensor's fixed pattern are slow
changes of single pixels, and they read as "signal" there (examples/empty.mp4: 4.0 dB in green,
examples/walking.mp4: 4.1 dB). What tells a hidden person's shadow from them is averaging: a
shadow is spread over the wall, so its power survives block averaging while the noise falls, and
the block SNR grows with the block; pixel-level residue falls with the noise (the empty room:
0.1 dB at 32x32, the walker 6.8 dB). The verdict reads the green channel, as evaluate does. It
cannot rule a signal out where the SNR does not grow: a faint change of the whole wall (a jumper,
2.3 dB in activity's plots of examples/jumping.mp4) can stay under the pixel-level residue at
every block size; it says so rather than "no signal".
"""
from __future__ import annotations

from wallcli.wording import format_db

GREEN = 1
GROWTH_DB = 1.0  # how much averaging must raise the SNR over the 1x1 row to call it a spread signal
MIN_BLOCKS = 4  # a block size with fewer blocks in the ROI is too few samples to judge on


WHY = ("a shadow spread over the wall keeps its power when blocks are averaged while the noise falls, "
       "so its block SNR grows; codec residue and sensor pattern are per pixel and read a few dB at 1x1 "
       "even on an empty wall")


def snr_verdict(result: dict) -> dict:
    """``{"signal", "block", "snr_db", "text", "why"}`` from an ``snr --json`` object: ``signal`` is True
    when some block size of 2x2 and up carries the green channel's SNR above 0 dB and at least
    GROWTH_DB over the 1x1 row; ``block`` and ``snr_db`` name the best block size and its SNR."""
    scales = result["scales"]
    one = next(s for s in scales if s["block"] == 1)["snr_db"][GREEN]
    judged = [s for s in scales if s["block"] > 1 and s.get("blocks", MIN_BLOCKS) >= MIN_BLOCKS] or scales
    best = max(judged, key=lambda s: s["snr_db"][GREEN])
    top, k = best["snr_db"][GREEN], best["block"]
    signal = bool(top > 0 and top >= one + GROWTH_DB)
    at = f"{k}x{k}"
    # every text quotes the figure the JSON gives (``snr_db``, at ``block``) and names its block:
    # the 1x1 figure it once quoted disagreed with the JSON (jumping.mp4: 6.5 dB said, 5.0 given);
    # the 1x1 row is the table's first, under this line
    # named "block SNR": the headline figure above it (column SNR) is another one
    figure = f"block SNR green {format_db(top)} dB at {at}"
    if signal:
        text = f"a signal above the noise, best at {at}: block SNR green {format_db(top)} dB"
    elif max(one, top) <= 0:
        text = f"no signal at any block size ({figure})"
    else:
        # not "no signal": a broad, faint change (a jumper dims the whole wall a little) can sit
        # under pixel-level residue at every block size, and the plots' bins still show it
        text = f"no wall signal ({figure}, no averaging gain)"
    return {"signal": signal, "block": k, "snr_db": top, "text": text, "why": WHY}
