#!/usr/bin/env bash
# The README's picture of a report: `wallcli report` on the bundled walking clip, rendered by
# headless Chromium with the flags the browser tests use, the top of the page kept and shrunk
# into examples/report.png (a few hundred KB at most). Needs chromium (Debian: apt-get install chromium).
set -euo pipefail
cd "$(dirname "$0")/.."
W=${WALLCLI:-.venv/bin/wallcli}
PY=${PYTHON:-$PWD/.venv/bin/python}
# the page goes to out/ at the top of the checkout, outside examples/ (see pipeline.sh); it is made
# by the very command the README's caption gives (the page records its command), so no --force
mkdir -p out
rm -f out/report.html
$W report examples/walking.mp4 -o out/report.html
cd examples
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
  --disable-component-update --disable-sync --hide-scrollbars --user-data-dir="$profile" \
  --window-size=1100,2000 --screenshot="$PWD/../out/report-full.png" "file://$PWD/../out/report.html" 2>/dev/null
"$PY" - <<'PYEOF'
from PIL import Image

with Image.open("../out/report-full.png") as im:
    im = im.convert("RGB")
    small = im.resize((im.width * 6 // 10, im.height * 6 // 10), Image.LANCZOS)
small.quantize(colors=256, method=Image.Quantize.MEDIANCUT).save("report.png", optimize=True)
PYEOF
ls -l report.png >&2
