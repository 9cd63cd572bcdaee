#!/usr/bin/env bash
# Renders the README's scanned-head figure and RMSE table: `rtbake run tap-grid --separable` on the Lee Perry-Smith
# scan ("Infinite, 3D Head Scan" by Lee Perry-Smith / Infinite-Realities, CC BY 3.0) at 640x360, then writes the
# contact sheet at half size as JPEG into docs/figures/ (Pillow) and prints the RMSE table as Markdown.
#
# Usage: bash scripts/scan_figures.sh [HEADS_DIR]   (default: ../shared/reference/heads/lee-perry-smith)
# Needs: the debug binary (`cargo build --locked`), the scan, python3 with Pillow.
set -euo pipefail
cd "$(dirname "$0")/.."
heads="${1:-../shared/reference/heads/lee-perry-smith}"
for f in LeePerrySmith.glb color.jpg normal.jpg; do
    [ -f "$heads/$f" ] || { echo "scan_figures: $heads/$f is missing (see ../shared/reference/heads/)" >&2; exit 2; }
done
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
target/debug/rtbake --json run tap-grid --separable --mesh "$heads/LeePerrySmith.glb" --mesh-units auto --uv-origin bottom-left \
    --albedo "$heads/color.jpg" --normal-map "$heads/normal.jpg" --width 640 --height 360 --out "$out/grid" \
    > "$out/grid.json"
python3 - "$out" <<'PY'
import json, sys
from PIL import Image
out = sys.argv[1]
sheet = Image.open(f"{out}/grid/contact_sheet.png").convert("RGB")
half = sheet.resize((sheet.width // 2, sheet.height // 2), Image.LANCZOS)
half.save("docs/figures/scan_tap_grid_640x360.jpg", quality=85, optimize=True)
v = json.load(open(f"{out}/grid.json"))
cols = ["ss-full", "ss-jittered", "separable", "no-sss"]
names = {"ss-full": "SS Full", "ss-jittered": "SS Jittered", "separable": "Separable", "no-sss": "No SSS"}
rows = {}
for c in v["conditions"]:
    rows.setdefault((c["distance"], c["azimuth_deg"]), {})[c["shader"]] = c["rmse"]
print("| distance, azimuth | " + " | ".join(names[c] for c in cols) + " |")
print("| --- |" + " --- |" * len(cols))
for (d, a), r in rows.items():
    print(f"| {d}, {a:g}° | " + " | ".join(f"{r[c]:.4f}" for c in cols) + " |")
print("| mean of 12 | " + " | ".join(f"{v['mean_rmse'][c]:.4f}" for c in cols) + " |")
print(f"docs/figures/scan_tap_grid_640x360.jpg: {half.width}x{half.height}", file=sys.stderr)
PY
