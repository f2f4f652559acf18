#!/usr/bin/env bash
# Re-makes the pictures of the README and the book (docs/src/images/): three renders, an
# adaptive render beside its spp map, three renders through lens prescriptions, a moving
# camera's frames (instant, rolling shutter, motion blur, flow), a moving object's, the
# speed-against-error plot of results/lavapipe/ and its plot in rays, and the strip the README opens with. Run from
# anywhere after `cargo build --release`; about a minute on lavapipe. Needs python3 with
# Pillow (`.ci/install-lavapipe` installs it). Each picture is kept under 300 KB.
set -euo pipefail
cd "$(dirname "$0")/.."
fisheye=target/release/fisheye
out=docs/src/images
mkdir -p "$out"
# The default room through the 180° Canon 8-15 mm at 8 mm (the first command of the README).
"$fisheye" render --size 400x300 -o "$out/room.png"
# Šibenik cathedral through the Samyang 7.5 mm's real mapping (a preset fitted to the lens).
"$fisheye" render scenes/sibenik.toml --lens samyang-7.5mm --size 400x300 -o "$out/sibenik.png"
# A glTF file (scenes/gltf/pavilion.glb: shared meshes placed by instances, PBR colours, no
# lights: the headlight and sun this tool adds, exposed automatically), from inside the ring.
"$fisheye" render scenes/gltf/pavilion.glb --camera 1.2,1.8,4.2:0,0.6,0 --size 400x300 \
  -o "$out/gltf.png"
# Adaptive sampling: the room with --spp auto and its spp map, side by side.
"$fisheye" render --size 400x300 --spp auto --outputs spp -o "$out/adaptive-room.png"
python3 - "$out" <<'PY'
import sys
from PIL import Image

out = sys.argv[1]
room = Image.open(f"{out}/adaptive-room.png").convert("RGBA")
rays = Image.open(f"{out}/adaptive-room.spp.png").convert("RGBA")
pair = Image.new("RGBA", (room.width * 2 + 8, room.height), (255, 255, 255, 255))
pair.alpha_composite(room, (0, 0))
pair.alpha_composite(rays, (room.width + 8, 0))
pair.convert("RGB").save(f"{out}/adaptive.png", optimize=True)
PY
rm -f "$out/adaptive-room.png" "$out/adaptive-room.spp.png"
# Real glass: Muller's fisheye through its fitted model (an ideal lens of the same mapping),
# the same lens traced through its glass (vignetting, the image circle), and the double Gauss
# wide open at f/2 focused at 2 m (depth of field), side by side.
"$fisheye" render --lens prescription:lenses/fisheye-10mm.dat,rays=fit --size 400x300 --spp 16 \
  -o "$out/glass-fit.png"
"$fisheye" render --lens prescription:lenses/fisheye-10mm.dat --size 400x300 --spp 64 \
  -o "$out/glass-fisheye.png"
"$fisheye" render --lens prescription:lenses/dgauss-50mm.dat,sensor=30,focus=2 --size 400x300 \
  --spp 64 -o "$out/glass-dgauss.png"
python3 - "$out" <<'PY'
import sys
from PIL import Image

out = sys.argv[1]
tiles = [Image.open(f"{out}/glass-{n}.png").convert("RGBA") for n in ("fit", "fisheye", "dgauss")]
row = Image.new("RGBA", (sum(t.width for t in tiles) + 8 * (len(tiles) - 1), 300), "white")
x = 0
for t in tiles:
    row.alpha_composite(t, (x, 0))
    x += t.width + 8
row = row.convert("RGB").resize((row.width * 2 // 3, 200), Image.LANCZOS)
row.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.FLOYDSTEINBERG).save(
    f"{out}/glass.png", optimize=True
)
PY
rm -f "$out"/glass-fit.png "$out"/glass-fisheye.png "$out"/glass-dgauss.png
# Three frames (instant, rolling, blur) and the instant's optical flow (hue: direction,
# saturation: length; grey where the next frame does not see the point), side by side:
# python3 "$row_py" PICTURE SETS FRAME.
row_py=$(mktemp)
cat > "$row_py" <<'PY'
import colorsys, sys
import numpy as np
from PIL import Image

path, sets, frame = sys.argv[1], sys.argv[2], sys.argv[3]
tiles = [Image.open(f"{sets}/{n}/{frame}.png").convert("RGB") for n in ("instant", "rolling", "blur")]
flow = np.load(f"{sets}/instant/{frame}.flow.npy")
valid = np.load(f"{sets}/instant/{frame}.flow_valid.npy").astype(bool)
u, v = np.nan_to_num(flow[..., 0]), np.nan_to_num(flow[..., 1])
length = np.hypot(u, v)
hue = (np.arctan2(v, u) / (2 * np.pi)) % 1.0
sat = np.clip(length / max(np.percentile(length[valid], 99), 1e-9), 0, 1)
rgb = np.array([colorsys.hsv_to_rgb(h, s, 1.0) for h, s in zip(hue.ravel(), sat.ravel())])
rgb = rgb.reshape(flow.shape[:2] + (3,))
rgb[~valid] = 0.5
tiles.append(Image.fromarray((rgb * 255).round().astype(np.uint8)))
row = Image.new("RGB", (sum(t.width for t in tiles) + 8 * (len(tiles) - 1), 300), "white")
x = 0
for t in tiles:
    row.paste(t, (x, 0))
    x += t.width + 8
row = row.resize((row.width // 2, 150), Image.LANCZOS)
row.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.FLOYDSTEINBERG).save(
    path, optimize=True
)
PY
# Time in the camera: the room through the Samyang turning 6 rad/s about the vertical while
# sliding 3 m/s to the side: the frame at an instant, read by a rolling shutter (0.5 ms a
# line: verticals lean), exposed for 15 ms (motion blur), and its optical flow to the next
# frame (hue: direction, saturation: length; grey where the next frame does not see the
# point), side by side.
time_dir=$(mktemp -d)
python3 - "$time_dir/yaw.tum" <<'PY'
import math, sys
# Eye at the room's default camera, looking along -z (180° about x), turning about +y.
with open(sys.argv[1], "w") as f:
    for k in range(7):
        t = 0.05 * k
        a = 6.0 * t / 2
        # q_yaw(6t) * q_x(180°) as x y z w.
        qx, qy, qz, qw = math.cos(a), 0.0, -math.sin(a), 0.0
        f.write(f"{t:.2f} {-0.3 + 3.0 * t:.3f} 1.5 2.5 {qx} {qy} {qz} {qw}\n")
PY
for setup in "instant:--spp 4" "rolling:--spp 4 --line-delay 0.0005" "blur:--spp 16 --exposure-time 0.015"; do
  name=${setup%%:*}
  # shellcheck disable=SC2086
  "$fisheye" dataset render --trajectory "$time_dir/yaw.tum" --lens samyang-7.5mm \
    --size 400x300 ${setup#*:} --outputs flow -o "$time_dir/$name" > /dev/null 2>&1
done
python3 "$row_py" "$out/time.png" "$time_dir" cam0/000002_0.10
rm -rf "$time_dir"
# Moving objects: scenes/dataset/sliding.toml's box sliding 2 m/s and turning 90°/s past a
# still camera, at 0.5 s: an instant, a rolling shutter (1 ms a line: the box leans), a
# 0.1 s exposure (it blurs), and the instant's flow (the box's own motion), side by side.
moving_dir=$(mktemp -d)
printf '0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n' > "$moving_dir/still.tum"
for setup in "instant:--spp 4" "rolling:--spp 4 --line-delay 0.001" "blur:--spp 16 --exposure-time 0.1"; do
  name=${setup%%:*}
  # shellcheck disable=SC2086
  "$fisheye" dataset render scenes/dataset/sliding.toml --trajectory "$moving_dir/still.tum" \
    --lens rectilinear:f=1.2 --size 400x300 --frame-rate 4 ${setup#*:} --outputs flow \
    -o "$moving_dir/$name" > /dev/null 2>&1
done
python3 "$row_py" "$out/moving.png" "$moving_dir" cam0/000002_0.500000
rm -rf "$moving_dir" "$row_py"
python3 - "$out" <<'PY'
import sys
from PIL import Image

out = sys.argv[1]
plot = Image.open("results/lavapipe/sibenik/compare/tradeoff-flip.samyang-7.5mm.png").convert("RGB")
height = 300
plot = plot.resize((round(plot.width * height / plot.height), height), Image.LANCZOS)
plot.save(f"{out}/tradeoff.png", optimize=True)
# The verdict in rays: many-small through the Samyang, RT's rays against the traced cube's texels.
rays = Image.open("results/lavapipe/many-small/compare/rays.samyang-7.5mm.png").convert("RGB")
rays = rays.resize((rays.width * 8 // 11, rays.height * 8 // 11), Image.LANCZOS)
rays.save(f"{out}/rays.png", optimize=True)
tiles = [Image.open(f"{out}/{n}.png").convert("RGB") for n in ("room", "gltf", "sibenik")]
tiles.append(plot)
strip = Image.new("RGB", (sum(t.width for t in tiles) + 8 * (len(tiles) - 1), height), "white")
x = 0
for t in tiles:
    strip.paste(t, (x, 0))
    x += t.width + 8
strip = strip.resize((strip.width * 2 // 3, height * 2 // 3), Image.LANCZOS)
strip.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.FLOYDSTEINBERG).save(
    f"{out}/strip.png", optimize=True
)
PY
ls -l "$out"
