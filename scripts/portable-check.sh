#!/usr/bin/env bash
# x86-64 builds target x86-64-v3 (.cargo/config.toml). This checks the
# promise made there: a build for the x86-64 base gives the same frames,
# byte for byte. It renders the showcase (frames 0 and 17) and, where
# ../shared/assets exists, three benchmark cases (trilinear textures and a
# normal map; MSAA with a PCF shadow map and a floor; glTF PBR) with both
# builds, and compares the files. It then renders the same with the
# x86-64-v3 build at every lane width (SOFTRASTER_LANES=1, 4, 8) and with
# the base build at 1 and 4, and compares those too. Exit 0 when all
# match.
#
#   bash scripts/portable-check.sh
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(uname -m)" != "x86_64" ]; then
    echo "portable-check: not x86-64, nothing to compare"
    exit 0
fi
cargo build --release --quiet
RUSTFLAGS="-C target-cpu=x86-64" cargo build --release --quiet --target-dir target/portable
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
render() {
    local bin=$1 dir=$2
    "$bin" render scenes/showcase.toml --frames 0,17 --quiet --out "$dir/showcase" >/dev/null
    if [ -d ../shared/assets ]; then
        "$bin" bench --case diablo3-matched --frames 3 --out "$dir/matched" >/dev/null
        "$bin" bench --case diablo3-matched-shadow --msaa 4 --frames 2 --out "$dir/shadow" >/dev/null
        "$bin" bench --case flighthelmet --frames 2 --out "$dir/helmet" >/dev/null
    fi
}
render target/release/softraster "$out/v3"
render target/portable/release/softraster "$out/base"
# Every lane width gives the same bytes (the default is the widest).
for w in 1 4 8; do
    SOFTRASTER_LANES=$w render target/release/softraster "$out/lanes-v3-$w"
done
for w in 1 4; do
    SOFTRASTER_LANES=$w render target/portable/release/softraster "$out/lanes-base-$w"
done
if [ ! -d ../shared/assets ]; then
    if [ "${CI:-}" = "true" ]; then
        echo "portable-check: FAIL: ../shared/assets is missing"
        exit 1
    fi
    echo "portable-check: SKIPPED the benchmark cases (no ../shared/assets)"
fi
n=$(find "$out/v3" -type f | wc -l)
if diff -r "$out/v3" "$out/base"; then
    echo "portable-check: $n files, x86-64-v3 and x86-64 builds byte-identical"
else
    echo "portable-check: FAIL: the x86-64-v3 and x86-64 builds differ"
    exit 1
fi

for run in lanes-v3-1 lanes-v3-4 lanes-v3-8 lanes-base-1 lanes-base-4; do
    if ! diff -r "$out/v3" "$out/$run"; then
        echo "portable-check: FAIL: $run differs from the default width"
        exit 1
    fi
done
echo "portable-check: lane widths 1, 4 and 8 (x86-64-v3) and 1, 4 (x86-64) byte-identical"
# The base build has no eight lanes: asking for them exits 2, naming it.
set +e
SOFTRASTER_LANES=8 target/portable/release/softraster render scenes/showcase.toml \
    --out "$out/refused" --quiet 2>"$out/err"
code=$?
set -e
if [ "$code" != 2 ] || ! grep -q "SOFTRASTER_LANES=8" "$out/err"; then
    echo "portable-check: FAIL: the x86-64 build took SOFTRASTER_LANES=8 (exit $code)"
    exit 1
fi
