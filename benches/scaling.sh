#!/usr/bin/env bash
# How softraster's per-frame time grows with pixels and with triangles, on 1
# and 2 threads: the diablo3-matched workload (the llvmpipe harness's set-up)
# at 350^2 .. 2800^2, and subdivided 0..4 times (5k .. 1.29M triangles, the
# same pixels) at 700^2. Prints a markdown table of steady ms/frame (median
# of frames 1..n), best of REPEATS runs.
#   cargo build --release && bash benches/scaling.sh
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-target/release/softraster}
FRAMES=${FRAMES:-24}
REPEATS=${REPEATS:-2}
ASSETS=${ASSETS:-../shared/assets}
best() { # case size threads
  local b=""
  for _ in $(seq "$REPEATS"); do
    local t json
    # The JSON line, not the table: a column added to the table (the
    # environment's prefilter time) once shifted the one read here.
    json=$(mktemp)
    "$BIN" bench --assets "$ASSETS" --case "$1" --size "$2" --threads "$3" --frames "$FRAMES" \
      --json "$json" > /dev/null
    t=$(python3 -c "import json, sys; print(json.loads(open(sys.argv[1]).readline())['frame_median_ms'])" "$json")
    rm -f "$json"
    b=$(python3 -c "print(min(float('$t'), float('${b:-inf}')))")
  done
  printf "%.2f" "$b"
}
echo "| workload | 1 thread ms/frame | 2 threads ms/frame | 2-thread speed-up |"
echo "|---|---|---|---|"
for s in 350 700 1400 2800; do
  a=$(best diablo3-matched $s 1); b=$(best diablo3-matched $s 2)
  echo "| diablo3-matched ${s}x${s} | $a | $b | $(python3 -c "print(f'{$a/$b:.2f}')") |"
done
for c in tris-5k tris-20k tris-80k tris-320k tris-1m; do
  a=$(best $c 700 1); b=$(best $c 700 2)
  echo "| $c 700x700 | $a | $b | $(python3 -c "print(f'{$a/$b:.2f}')") |"
done
