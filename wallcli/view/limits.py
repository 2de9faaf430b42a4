"""The view check's thresholds and the issues it names (see :mod:`wallcli.view.check`): every
threshold in units of the noise the clip itself shows, but for the floors that encode the method's
own premise (``REL``: no hidden person changes the wall by that much; ``MIN_SHIFT``: a tripod's
sub-pixel shake, which corrections deal with). Each says why it is what it is."""
from __future__ import annotations

MAX_SIDE = 320  # registration scale: finer texture than this is not needed to see a pan
BLOCKS = 40  # blocks along the long side for movers and cuts: a person in view covers several
K_MOVER = 8.0  # a block changed by this many noise sigmas (and REL) from its slow background
REL_EDGE = 0.05  # whose fine structure changed by an RMS over this fraction of the level (REL: no
# hidden person changes the wall by that much, outline or not)
K_EDGE = 4.0  # and this many spreads above the frame's median block residual (its noise, texture
# and codec residue in the fine band): the RMS of n pixels spreads by about median/sqrt(2 n), n
# counted as a quarter of the block's pixels (see K_SHIFT); a block of a 96-pixel-wide frame is 2x2
# pixels, of a 320-pixel one 8x8 (three refused some transfer-set walls as movers; six
# missed a 40-60 % sprite on a dark noisy wall that four catches)
SHARP = 0.15  # and over this fraction of the step it bounds (the largest change among the block and
# its 8 neighbours): an in-focus outline (blurred by a pixel or less) puts 0.09-0.11 of its step into
# the fine band on its own and the wall texture it hides adds to that (simulated objects: 0.2 and
# more), a penumbra of 4 px or more puts under 0.05; deep simulated shadows (half the level) reached
# 0.13 with the codec's re-coding residue on top. Session 17 (research/view/README.md):
# with a floor of 10 % of the level alone, faint objects (15-40 % contrast) were caught a quarter of
# the time, while hard shadows of people 1-2 m from the wall (half the level, the codec re-coding
# them) were refused as movers; these three together catch more of the one and none of the other
FINE = 2.0  # pixels (at the registration scale): the outline's scale
EDGE_LEVEL = 40.0  # code values: under it, the level floor (noise, not contrast, rules dark walls)
K_CUT = 8.0
REL = 0.05  # of the local level: above any hidden person's shadow
REL_CUT = 0.02  # one frame to the next: a shadow moves, it does not change a fifth of the wall at once
CUT_FRACTION = 0.2  # of the usable blocks (simulated walls: at most 1.5 %; cuts between two: 40 % and more)
CUT_SIDE = 160  # samples along the long side for the cut watch (4x4 per block at 16:9)
CUT_RATE = 15.0  # frames a second the cut watch compares (every other frame at 30 fps): a cut is
# one jump between any two of them, while a sweeping shadow changes a sample pair 2 frames apart
# by a third of what 6 frames (a full check's spacing) did on the walls measured
CUT_CALM = 0.1  # the frames before and after a cut (a codec settling after one, a shadow: up to 9 %)
# A cut between two views of alike walls can change under a fifth of the blocks by 2 %: most of the
# change is then the frame's gain, which is divided out, and a little of its spatial pattern. What is
# left is coarse (the other room's shading) and comes in one step, while the codec's re-coding is
# fine-grained and a person's light changes over many frames. So the gain-free step is also read on
# CUT_CELLS cells along the long side, as an RMS relative to the level: a cut is a step CUT_SPIKE
# times the clip's median step and each of the CUT_REACH steps on either side, and over REL_CUT / 2
# (no hidden person changes that much of the wall's pattern between two samples). Session 18
# (research/view/README.md): steps over the floor reached at most 2.7 times on 220 walls; the 15
# cuts the changed share missed, 2.0-48 times (13 over 4)
CUT_CELLS = 8
CUT_SPIKE = 4.0
CUT_REACH = 2
MIN_MOVER_BLOCKS = 2
MIN_SHIFT = 1.5  # source pixels from the reference frame
# the fewest samples on each side, at the check's scale, that a shift is registered on: a pan of a
# 30x30 or 8x8 frame passed as still (40x40: caught)
MIN_REGISTER_SIDE = 33
MIN_CROP = 8  # an ROI's side under which its images are too small for the check to look at at all
K_SHIFT = 3.0  # z-score of the shift's fit against its mirror image (see view_motion._shift_fits), held over
HOLD, HOLD_WITHIN = 3, 8  # agreeing frames among the last few: the phase correlation picks the best
# of many shifts, so noise alone scores a few, but its peaks land anywhere; on a noisy wall the
# true peak wins only in some frames, so agreement is asked of 3 of 8, not of 3 in a row
DARK = 10.0  # 8-bit code values: 1 % of the level is then a tenth of a quantisation step
CLIP_HI = 250.0
MIN_USABLE = 0.5  # of the frame's area, neither clipped nor dark
SIGMA_FLOOR = 0.02  # code values: a frozen (repeated) frame has no measurable noise
HISTORY = 64  # frames whose noise estimates are pooled (a median: a cut or a mover does not move it)
MAX_SPANS = 64  # per kind; more are merged, so memory stays bounded
GAP_EDGE = 0.05  # s: a window touching a frame gap by under this (one 30 fps grid step and rounding) spans none of it
MAX_OBJECT_HITS = 600  # 'moving object' flags kept to be taken back when an overlay is found (ViewCheck.mask)
CHECK_RATE = 3.0  # frames checked per second of a calm view: checking every frame cost more than
# the analysis itself (3-5 ms a 1080p frame against about 3 for decoding and the plots;
# bench/RESULTS.md). After a check that finds anything suspect (a shift that fits, a block far off
# its background; or a frame of the cut watch with a large changed share) every frame is checked
# for DENSE seconds, so the rules that ask for agreement between neighbouring frames (a shake's
# shifts) and a mover's outline get every frame's chance, as before
DENSE = 0.5
MATCH_RATE = 1.0  # checks a second that learn the texture and colour and measure how registrable the
# wall is (see REGISTRABLE): each is a few tenths of a ms, and light and texture change slowly

TEX_TAU = 4.0  # seconds: the wall's texture is learnt where nothing changed, over this time
EDGE_GRAD = 0.02  # of the level a pixel, at the outline's scale FINE: a step of 10 % (a wall's texture
# of a few per cent a pixel, blurred by FINE, stayed under 0.9 % on the bundled examples)
K_OUTLIER = 3.0  # RMS of the calm blocks: beyond it a pixel of either texture is an edge, not texture
# A region is an object when (any of):
# - the wall's texture is gone: its regression on the learnt texture is under KEPT of the calm
#   blocks' by K_TEX standard errors (with MIN_KNOWN blocks' worth of pixels that are no edge).
#   Not a half: a compressed wall's calm blocks are copied from frame to frame, frozen noise and
#   all, while the codec re-codes a moving shadow and keeps a tenth to a half of the texture there
#   (sharp-shadow walls at CRF 18: 0.1-0.4; the same walls lossless: all of it);
# - it is flat: FLAT_SHARE % of its blocks hold under FLAT of the calm blocks' relative fine
#   energy (at their level): neither the wall's texture nor the noise that light brings;
# - its colour ratios moved by over COLOUR (on COLOUR_BLOCKS blocks or more, of a background level
#   of COLOUR_LEVEL or more: a small deep shadow under two lights of other colours moved them by up
#   to 0.25, a shadow taking half the light of a room lit in two colours by 0.10, and on a wall of
#   level 30 a ratio's quantisation alone is 0.03). On the simulator's objects it adds next to
#   nothing to the two rules above; it is there for real objects on walls with no texture.
# Chosen on session 19's first 16 rounds (research/view/README.md); COLOUR_LEVEL and COLOUR 0.15
# after false alarms of the whole sample were seen (walls of level 30; the half-light shadow).
MIN_KNOWN = 4
KEPT = 0.1
K_TEX = 4.0
FLAT, FLAT_SHARE = 0.02, 10
COLOUR, COLOUR_BLOCKS, COLOUR_LEVEL = 0.15, 4, 60.0
NOTES = {"sharp light": "sharp shadow or light in view: a person near the wall or a small light"}

REGISTRABLE = 8.0  # standard errors: the best texture match with the reference frame (see
# _texture_match; in place, or moved by the shift found) over the last checks, of a wall whose
# camera motion can be verified: under it the texture is under the
# noise, and a shift the correlation finds is no proof
SHIFT_Z = 3.0  # standard errors by which the reference moved by the shift must fit better than in place
# (session 19: four still walls had the finest band's two within 0.3-1.5 and the other band's reversed)
NOT_REFUSED = ("motion not verifiable",)  # issues that say what could not be checked; answers stand

KINDS = {
    "camera motion": "the camera moved",
    "motion not verifiable": "the wall has no texture to register on: whether the camera moved is not known",
    "moving object": "something moved in view",
    "scene cut": "the shot changes",
    "clipped": "much of the frame is clipped",
    "too dark": "much of the frame is too dark",
    "too little usable area": "too little of the frame is usable",
    "too thin to check": "the frame is too thin to check for camera motion",
    "too small to check": f"the frame (or ROI) is too small to check for camera motion (it needs "
                          f"{MIN_REGISTER_SIDE}x{MIN_REGISTER_SIDE} pixels or more)",
    # not the view's fault but the file's: frames lost (their timestamps jump, io.video.GAP_FACTOR);
    # nothing spanning it is continuous video
    "frame gap": "frames are missing",
}