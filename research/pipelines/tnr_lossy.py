"""Issue 45 part 2 (session 23): can a blend be read on the noise alone on the transfer set's lossy
clips? Per clip, on the tiles of wallcli.camera.tnr (differences of luma pixels two columns apart),
each frame's tile regressed on the tile's mean texture and a constant (the light the whole tile
shares, scaled texture included) and then: lag1 = median over tiles of d_2 / d_1 - 1; R = the
variance of second differences at stride 2 over stride 1 (a linear trend, what a person's slow
light leaves, cancels; 1 for white noise, 1.81 for a blend of 0.65); held = share of 8x8 blocks
unchanged. Not shipped: README_tnr_awb.md says why (neither separates on lossy sources).

    PYTHONPATH=. python research/pipelines/tnr_lossy.py /tmp/m45/*_tnr*.mkv
"""
import sys, json
import numpy as np
from wallcli.io.video import open_video
from wallcli.camera.tnr import _tiles, TILE

def stats(path, max_frames=400):
    with open_video(path) as r:
        zs = []; held = []; corners = None; prev = None
        for i, f in enumerate(r.frames()):
            y = f.planes.y
            if corners is None: corners = _tiles(*y.shape)
            luma = np.stack([y[a:a+TILE, c:c+TILE+2] for a, c in corners]).astype(np.float32)
            zs.append(luma[:, :, 2:] - luma[:, :, :-2])
            if prev is not None:
                held.append((np.abs(luma[:,:,:TILE]-prev[:,:,:TILE]).reshape(len(luma),TILE//8,8,TILE//8,8).max(axis=(2,4))==0).mean())
            prev = luma
            if i >= max_frames: break
    z = np.stack(zs)  # T, tiles, 16, 16
    # remove per frame per tile the texture's scale: regress on the tile's mean z and a constant
    zb = z.mean(0)
    T, n = z.shape[:2]
    X = np.stack([np.ones_like(zb), zb], -1).reshape(n, -1, 2)
    zr = z.reshape(T, n, -1)
    out = np.empty_like(zr)
    for j in range(n):
        b = np.linalg.lstsq(X[j], zr[:, j].T, rcond=None)[0]
        out[:, j] = zr[:, j] - (X[j] @ b).T
    zr = out
    D1 = zr[2:] - 2 * zr[1:-1] + zr[:-2]
    D2 = zr[4:] - 2 * zr[2:-2] + zr[:-4]
    v1 = np.square(D1).mean(axis=(0, 2)); v2 = np.square(D2).mean(axis=(0, 2))
    R = float(np.median(v2 / v1))
    d1 = np.square(zr[1:] - zr[:-1]).mean(axis=(0, 2)); d2 = np.square(zr[2:] - zr[:-2]).mean(axis=(0, 2))
    d4 = np.square(zr[4:] - zr[:-4]).mean(axis=(0, 2))
    return {"R": round(R, 3), "lag1": round(float(np.median(d2/d1)) - 1, 3), "d4/d2": round(float(np.median(d4/d2)), 3), "held": round(float(np.mean(held)), 4)}

for p in sys.argv[1:]:
    print(json.dumps({"file": p.split("/")[-1], **stats(p)}), flush=True)
