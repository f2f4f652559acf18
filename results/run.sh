#!/usr/bin/env bash
# Reproduces a results folder: `fisheye compare` and `fisheye bench` on the issue's scenes
# (the built-in many-small and few-detailed, and the shared Sibenik, Cornell box, bunny and
# Buddha), through a 180° equidistant fisheye (canon-8-15mm@8mm), the Samyang equisolid preset
# and the pinhole baseline; then the thesis's face sizes (512, 1024, 1920) at 1024x768.
#
#   bash results/run.sh results/NAME   # SIZE, CUBES, BENCH_CUBES, FRAMES, SCENES, THESIS override
#
# The defaults suit a CPU (lavapipe): 384x288 images, and cube faces scaled with the image from
# the issue's 512/1024/1920 at 1024x768 (x 3/8: 192, 384, 720). On a GPU use SIZE=1024x768
# CUBES=512,1024,1920 BENCH_CUBES=512,1024,1920 FRAMES=60. Error maps and reference images are
# kept for the first scene only (FIRST=0: for none), to keep the folder small.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: bash results/run.sh OUT_DIR}
size=${SIZE:-384x288}
cubes=${CUBES:-192,384,720}
bench_cubes=${BENCH_CUBES:-192,384}
frames=${FRAMES:-12}
bin=target/release/fisheye
cargo build --release --quiet
lenses=(--lens canon-8-15mm@8mm --lens samyang-7.5mm)
first=${FIRST:-1}
scenes=${SCENES:-builtin:many-small builtin:few-detailed scenes/sibenik.toml \
scenes/cornell-box.toml scenes/bunny.toml scenes/buddha.toml}
for scene in $scenes; do
    name=$(basename "${scene#builtin:}" .toml)
    "$bin" compare "$scene" "${lenses[@]}" --size "$size" --cube-size "$cubes" --frames 3 \
        -o "$out/$name/compare"
    if [ "$first" = 0 ]; then
        rm -f "$out/$name/compare/"*.error.png "$out/$name/compare/"*.reference.png \
            "$out/$name/compare/"*.supersampled.png
    fi
    first=0
    "$bin" bench "$scene" "${lenses[@]}" --size "$size" --cube-size "$bench_cubes" \
        --frames "$frames" --warmup 2 -o "$out/$name/bench"
done
# Lens validation: every preset and calibrated example. Two overlays are kept, and no
# per-corner lists, to keep the folder small.
"$bin" validate -o "$out/validate"
find "$out/validate" -name 'overlay.*' ! -name 'overlay.kb_*' ! -name 'overlay.canon-8-15mm@8mm.png' \
    -delete
rm -f "$out/validate/points."*.csv
# The thesis's face sizes at its kind of image size (THESIS=0 leaves it out).
[ "${THESIS:-1}" = 1 ] || exit 0
"$bin" compare builtin:many-small "${lenses[@]}" --no-pinhole --size 1024x768 \
    --method rt,cube-forward --cube-size 512,1024,1920 --frames 1 -o "$out/thesis-face-sizes"
rm -f "$out/thesis-face-sizes/"*.supersampled.png
