import csv, numpy as np
from wallcli.io.arrays import load_npz
from wallcli.signal.stplot import FORMAT, from_arrays
from wallcli.signal.window import resample, window_signal_db, remove_light_changes
rows = list(csv.DictReader(open("/work/shared/transfer/labels.csv")))
for r in rows:
    p = from_arrays(*load_npz(f"data/tp/{r['file'][:-4]}.npz", kind=FORMAT))
    h, _ = resample(p.horizontal, p.time); v, _ = resample(p.vertical, p.time)
    h, v = h[:, :256], v[:, :256]
    d3 = window_signal_db([(h, p.h_mean), (v, p.v_mean)])
    # without the light-change removal (just temporal mean)
    def raw_db(x):
        y = x - x.mean(1, keepdims=True); tot = (y**2).mean(); n = 0.5*(np.diff(y,axis=1)**2).mean(); return 10*np.log10(max(tot-n,1e-30)/n)
    print(f"{r['file'][:18]:18s} sig={float(r['signal']):.1e} {r['lighting']:14s} crf={r['crf']:>2s} v3={float(d3):6.1f} raw={raw_db(np.concatenate([h,v])):6.1f}")
