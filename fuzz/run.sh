#!/usr/bin/env bash
# Fuzz every reader for SECONDS seconds each (default 120) with the machine's nightly
# toolchain: `fuzz/run.sh [SECONDS] [TARGET...]`. Installs cargo-fuzz if it is missing.
# Seeds each corpus from the repository's own files (tests/fixtures, datasets); copies every
# crash into tests/corpus/TARGET/, which tests/corpus.rs reads in CI; prints one line per
# target with its executions and crashes (also written to fuzz/last-run.txt).
# FUZZ_SANITIZER=address runs under AddressSanitizer (13x slower here: 300 against 4,100
# executions a second on the VTK XML target); the default, none, finds panics, aborts,
# timeouts and out-of-memory at full speed (the crate has no unsafe code).
set -euo pipefail
cd "$(dirname "$0")"
SECONDS_EACH="${1:-120}"
shift || true
ALL="vtk_xml vtk_legacy obj off ply npy npz grid_csv series_csv png tiff mask_png svg json"
TARGETS="${*:-$ALL}"
if ! cargo +nightly fuzz --version >/dev/null 2>&1; then
    cargo install cargo-fuzz --locked
fi
ROOT=..
seed() { # target, files...
    local t=$1; shift
    mkdir -p "corpus/$t"
    for f in "$@"; do
        [ -f "$f" ] && [ "$(stat -c %s "$f")" -le 65536 ] && cp "$f" "corpus/$t/seed-$(basename "$f")"
    done
    return 0
}
F=$ROOT/tests/fixtures/vtk
seed vtk_xml $F/*.vti $F/*.vtp $F/*.vtu
seed vtk_legacy $F/*.vtk
seed obj $ROOT/datasets/horse_silhouette_2d.obj
seed off
seed ply
seed npy $ROOT/tests/fixtures/pandas/*.npy
seed npz $ROOT/tests/fixtures/pandas/*.npz
seed grid_csv $ROOT/datasets/soapfilm_piv_vorticity_63x63.csv
seed series_csv $ROOT/datasets/seattle_weather_daily_2012_2015.csv
seed png $ROOT/datasets/horse_mask.png
seed tiff
seed mask_png $ROOT/datasets/horse_mask.png
seed svg
seed json $ROOT/datasets/*.json
printf 'OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n' > corpus/off/seed-square.off
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float f\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 1\n1 0 0 2\n0 1 0 3\n3 0 1 2\n' > corpus/ply/seed-tri.ply
printf '<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100"><rect x="10" y="10" width="80" height="60"/><circle cx="50" cy="40" r="10" fill="white"/></svg>\n' > corpus/svg/seed-rect.svg
printf '1,2,3\n4,5,6\n7,8,0\n' > corpus/grid_csv/seed-small.csv
# a 4 x 3 8-bit grayscale TIFF, uncompressed
printf 'II*\0\010\0\0\0\011\0\0\001\003\0\001\0\0\0\004\0\0\0\001\001\003\0\001\0\0\0\003\0\0\0\002\001\003\0\001\0\0\0\010\0\0\0\003\001\003\0\001\0\0\0\001\0\0\0\006\001\003\0\001\0\0\0\001\0\0\0\021\001\004\0\001\0\0\0\172\0\0\0\025\001\003\0\001\0\0\0\001\0\0\0\026\001\003\0\001\0\0\0\003\0\0\0\027\001\004\0\001\0\0\0\014\0\0\0\0\0\0\0\0\001\002\003\004\005\006\007\010\011\012\013' > corpus/tiff/seed-4x3.tif
export TOPOSMOOTH_FUZZ_DIR="${TOPOSMOOTH_FUZZ_DIR:-/dev/shm}"
: > last-run.txt
for t in $TARGETS; do
    log="artifacts/$t.log"
    mkdir -p "artifacts/$t"
    # -rss_limit_mb: a run whose memory grows past it is a crash (inputs are at most 64 kB);
    # under AddressSanitizer -malloc_limit_mb also catches any single allocation above it
    cargo +nightly fuzz run "$t" --release -s "${FUZZ_SANITIZER:-none}" -- -max_total_time="$SECONDS_EACH" -max_len=65536 \
        -rss_limit_mb=4096 -malloc_limit_mb=512 -timeout=10 -print_final_stats=1 >"$log" 2>&1 || true
    runs=$(grep -a -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
    crashes=$(find "artifacts/$t" -type f \( -name 'crash-*' -o -name 'oom-*' -o -name 'leak-*' -o -name 'timeout-*' \) | wc -l)
    if [ "$crashes" -gt 0 ]; then
        mkdir -p "$ROOT/tests/corpus/$t"
        find "artifacts/$t" -type f \( -name 'crash-*' -o -name 'oom-*' -o -name 'timeout-*' \) -exec cp {} "$ROOT/tests/corpus/$t/" \;
    fi
    echo "$t: ${runs:-0} executions in ${SECONDS_EACH} s, $crashes crashes" | tee -a last-run.txt
done
