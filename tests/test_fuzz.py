"""Property-based fuzzing (Hypothesis) of the three readers of untrusted files: the .npz reader
(wallcli.io.arrays + the space-time plot check), the model-card loader (wallcli.infer.card) and the
video reader's container parsing (wallcli.io.video), fed mutated bytes of real files made here.

The property, everywhere: the reader returns a valid result or raises WallcliError (one line, exit
1 in the CLI); nothing else (no IndexError, no ZeroDivisionError, no hang). Examples are few and
derandomized so CI is fast and repeatable; WALLCLI_FUZZ_EXAMPLES=2000 explores further.
"""
from __future__ import annotations

import io
import json
import os
import shutil
import signal
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from clips import write_clip, write_plot

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from wallcli.errors import WallcliError  # noqa: E402

EXAMPLES = int(os.environ.get("WALLCLI_FUZZ_EXAMPLES", "60"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=EXAMPLES <= 200, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow,
                                       HealthCheck.data_too_large])
MODELS = Path(__file__).resolve().parents[1] / "models"
LIMIT = 30  # seconds per example: a reader that hangs fails instead of stalling CI


class _Hang(BaseException):
    pass


def _within_limit(fn, *args):
    def alarm(signum, frame):
        raise _Hang

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, LIMIT)
    try:
        return fn(*args)
    except _Hang:
        pytest.fail(f"{fn.__name__} ran past {LIMIT} s on a mutated file")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


# -------------------------------------------------------------------------------- mutations
@st.composite
def mutated(draw, data: bytes, head: int | None = None):
    """``data`` with a few byte flips, overwritten runs, deletions, insertions or a truncation;
    ``head`` biases the edits towards the first bytes (where containers keep their headers)."""
    buf = bytearray(data)
    for _ in range(draw(st.integers(1, 4))):
        if not buf:
            break
        end = len(buf) if head is None or draw(st.booleans()) else min(head, len(buf))
        at = draw(st.integers(0, end - 1))
        op = draw(st.sampled_from(["flip", "overwrite", "delete", "insert", "truncate"]))
        if op == "flip":
            buf[at] ^= 1 << draw(st.integers(0, 7))
        elif op == "overwrite":
            run = draw(st.binary(min_size=1, max_size=8))
            buf[at:at + len(run)] = run
        elif op == "delete":
            del buf[at:at + draw(st.integers(1, 64))]
        elif op == "insert":
            buf[at:at] = draw(st.binary(min_size=1, max_size=64))
        else:
            del buf[at:]
    return bytes(buf)


# -------------------------------------------------------------------------------------- .npz
@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz")
    plot = write_plot(folder / "p.npz", seconds=1.0)
    wall = lambda i: np.full((24, 32, 3), 120.0) + np.random.default_rng(i).normal(0, 2.0, (24, 32, 3))  # noqa: E731
    clips = {
        "mp4": write_clip(folder / "c.mp4", wall, 8),
        "mkv": write_clip(folder / "c.mkv", wall, 8, codec="ffv1", pix_fmt="yuv444p", options={}),
        "y4m": write_clip(folder / "c.y4m", wall, 8, codec="rawvideo", pix_fmt="yuv420p", options={}, fmt="yuv4mpegpipe"),
        "nut": write_clip(folder / "c.nut", wall, 8, codec="ffv1", pix_fmt="yuv420p", options={}, fmt="nut"),
    }
    return folder, plot, clips


def _load_plot(path):
    from wallcli.io.arrays import load_npz
    from wallcli.signal.stplot import FORMAT, from_arrays

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a NumPy warning escaping to the user is a defect too
        try:
            plot = from_arrays(*load_npz(path, kind=FORMAT), source=str(path))
        except WallcliError:
            return None
    assert plot.horizontal.dtype == np.float32 and np.isfinite(plot.horizontal).all()
    assert plot.time.shape == (plot.horizontal.shape[1],)
    return plot


@FUZZ
@given(data=st.data())
def test_npz_reader_on_mutated_bytes(files, data):
    folder, plot, _ = files
    bad = folder / "bad.npz"
    bad.write_bytes(data.draw(mutated(plot.read_bytes())))
    _within_limit(_load_plot, bad)


def _members(path: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as z:
        return {name: z.read(name) for name in z.namelist()}


def _rezip(members: dict[str, bytes]) -> bytes:
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as z:
        for name, payload in members.items():
            z.writestr(name, payload)
    return out.getvalue()


@FUZZ
@given(data=st.data())
def test_npz_reader_on_mutated_members_of_a_valid_zip(files, data):
    # byte mutations mostly break the zip's CRCs; these reach np.load's .npy parsing and the metadata
    folder, plot, _ = files
    members = _members(plot)
    name = data.draw(st.sampled_from(sorted(members)))
    action = data.draw(st.sampled_from(["mutate", "header", "drop", "meta"]))
    if action == "mutate":
        members[name] = data.draw(mutated(members[name], head=128))
    elif action == "header":  # the .npy header: dtype, shape, order
        header = data.draw(st.sampled_from([
            "{'descr': '<f4', 'fortran_order': False, 'shape': (99999999999,), }",
            "{'descr': '|O', 'fortran_order': False, 'shape': (3,), }",
            "{'descr': '<c8', 'fortran_order': False, 'shape': (64, 30, 3), }",
            "{'descr': '<U5', 'fortran_order': False, 'shape': (64, 30, 3), }",
            "{'descr': '<f8', 'fortran_order': True, 'shape': (64, 30, 3), }",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 30, 3), }",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (), }",
        ]))
        text = header.encode("latin1")
        text += b" " * (-(len(text) + 11) % 64) + b"\n"
        members[name] = b"\x93NUMPY\x01\x00" + len(text).to_bytes(2, "little") + text + members[name][128:]
    elif action == "drop":
        del members[name]
    else:
        meta = json.loads(str(np.load(io.BytesIO(members["meta.npy"]), allow_pickle=False)[()]))
        key = data.draw(st.sampled_from(sorted(meta)))
        meta[key] = data.draw(st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
                                           lambda c: st.lists(c, max_size=4) | st.dictionaries(st.text(max_size=3), c,
                                                                                              max_size=3), max_leaves=8))
        buf = io.BytesIO()
        np.save(buf, np.array(json.dumps(meta)))
        members["meta.npy"] = buf.getvalue()
    bad = folder / "bad.npz"
    bad.write_bytes(_rezip(members))
    _within_limit(_load_plot, bad)


# -------------------------------------------------------------------------------- model cards
def _json_values():
    return st.recursive(st.none() | st.booleans() | st.integers(-2**70, 2**70) | st.floats() | st.text(max_size=8),
                        lambda c: st.lists(c, max_size=4) | st.dictionaries(st.text(max_size=6), c, max_size=4),
                        max_leaves=10)


def _paths(card, prefix=()):
    """Every key path in the card (dicts and lists), to pick one to mutate."""
    if isinstance(card, dict):
        for k, v in card.items():
            yield prefix + (k,)
            yield from _paths(v, prefix + (k,))
    elif isinstance(card, list):
        for i, v in enumerate(card):
            yield prefix + (i,)
            yield from _paths(v, prefix + (i,))


def _read_and_use(model: Path, plot: Path):
    """Load the card; a card that passes must also run: its numbers go into the inference."""
    from wallcli.infer.card import read_card
    from wallcli.infer.classify import classify_plot, load_plot
    from wallcli.infer.model import Model

    try:
        card = read_card(model)
    except WallcliError:
        return
    assert isinstance(card, dict)
    try:
        m = Model.load(model, task="count")
        classify_plot(m, load_plot(plot), stride=int(card["stride"]), source=str(plot))
    except WallcliError:
        pass


@pytest.fixture(scope="module")
def card_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cards")
    shutil.copy(MODELS / "count.onnx", folder / "m.onnx")
    return folder / "m.onnx", json.loads((MODELS / "count.json").read_text()), (MODELS / "count.json").read_bytes(), \
        write_plot(folder / "p.npz", seconds=9.0)


@FUZZ
@given(data=st.data())
def test_card_loader_on_mutated_bytes(card_files, data):
    model, _, raw, plot = card_files
    model.with_suffix(".json").write_bytes(data.draw(mutated(raw)))
    _within_limit(_read_and_use, model, plot)


@FUZZ
@given(data=st.data())
def test_card_loader_on_mutated_fields(card_files, data):
    model, card, _, plot = card_files
    card = json.loads(json.dumps(card))
    paths = list(_paths(card))
    for _ in range(data.draw(st.integers(1, 3))):
        path = data.draw(st.sampled_from(paths))
        parent = card
        try:
            for k in path[:-1]:
                parent = parent[k]
            if data.draw(st.booleans()):
                parent[path[-1]] = data.draw(_json_values())
            elif isinstance(parent, dict):
                parent.pop(path[-1], None)
        except (KeyError, IndexError, TypeError):
            continue  # an earlier mutation removed this path
    model.with_suffix(".json").write_text(json.dumps(card))  # NaN/Infinity too: Python writes them
    _within_limit(_read_and_use, model, plot)


# ------------------------------------------------------------------------------------ video
def _decode(path: Path):
    from wallcli.io.video import VideoWarning, open_video
    from wallcli.signal.stplot import compute_stplot

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", VideoWarning)  # damage is reported as warnings: expected here
        try:
            with open_video(path) as reader:
                plot = compute_stplot(reader, bins=8)
        except WallcliError:
            return
    assert np.isfinite(plot.horizontal).all() and plot.frames >= 2


@pytest.mark.parametrize("kind", ["mp4", "mkv", "y4m", "nut"])
def test_video_reader_on_mutated_containers(files, kind):
    folder, _, clips = files
    raw = clips[kind].read_bytes()
    bad = folder / f"bad.{kind}"

    @FUZZ
    @given(data=st.data())
    def run(data):
        bad.write_bytes(data.draw(mutated(raw, head=512)))
        _within_limit(_decode, bad)

    run()
