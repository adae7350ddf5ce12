#!/usr/bin/env bash
# Instructions per frame (valgrind callgrind "I refs"), one thread: the
# difference of a 6-frame and a 1-frame run, over 5. Exact and repeatable
# where timings on a shared machine are not.
#   cargo build --release && bash benches/instructions.sh diablo3-matched [--msaa 4]
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-target/release/softraster}
CASE=${1:?usage: instructions.sh CASE [bench args]}
shift
ir() {
  local n=$1
  shift
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$BIN" bench --case "$CASE" \
    --threads 1 --frames "$n" "$@" 2>&1 | grep "I *refs" | tr -d ', ' | cut -d: -f2
}
a=$(ir 6 "$@")
b=$(ir 1 "$@")
python3 -c "print('$CASE $*: %.1f M instructions/frame' % (($a - $b) / 5 / 1e6))"
