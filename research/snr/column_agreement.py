"""How the headline figure (column_snr_db, wallcli/snr/column.py) agrees with the labels' snr_db of the
rendered recordings: run with the recordings' folder at /work/shared/transfer (edit ROOT)."""
import csv, json, numpy as np
ROOT = "/work/shared/transfer"  # the rendered recordings (labels.csv and the clips)
from wallcli.io.video import open_video
from wallcli.snr.column import ColumnSnr, CALIBRATION_DB
rows = list(csv.DictReader(open(ROOT + '/labels.csv')))
out = []
for r in rows:
    with open_video(ROOT + '/' + r['file']) as rd:
        tap = ColumnSnr(fps=float(rd.info.fps))
        for fr in rd.frames():
            tap(fr)
    out.append((r['file'], r['snr_db'], r['crf'], tap.db()))
json.dump(out, open('column_agreement.json', 'w'))
lab = [(float(l), m - CALIBRATION_DB) for f, l, c, m in out if l]
L = np.array([a for a, b in lab]); M = np.array([b for a, b in lab])
off = np.median(L - M); print('calibration (median L-M) %.2f' % off)
E = np.array([m for f, l, c, m in out if not l])
M2 = M + round(off); d = M2 - L
print('n=%d r=%.3f median|diff| %.1f within3 %.2f within5 %.2f band agree %.2f' % (len(L), np.corrcoef(L, M)[0, 1], np.median(np.abs(d)), np.mean(np.abs(d) < 3), np.mean(np.abs(d) < 5), np.mean(np.digitize(M2, [0, 10]) == np.digitize(L, [0, 10]))))
for lo, hi in ((-99, 0), (0, 10), (10, 99)):
    m = (L >= lo) & (L < hi)
    print('label band', lo, hi, m.sum(), 'measured bands', np.bincount(np.digitize(M2[m], [0, 10]), minlength=3))
Ec = E - CALIBRATION_DB + round(off)
print('empty rooms n=%d measured median %.1f p90 %.1f; bands' % (len(E), np.median(Ec), np.percentile(Ec, 90)), np.bincount(np.digitize(Ec, [0, 10]), minlength=3))
