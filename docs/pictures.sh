#!/usr/bin/env bash
# Re-makes the pictures of the README and the book (docs/src/images/): three renders, an
# adaptive render beside its spp map, three renders through lens prescriptions, the
# speed-against-error plot of results/lavapipe/, and the strip the README opens with. Run from
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
python3 - "$out" <<'PY'
import sys
from PIL import Image

out = sys.argv[1]
plot = Image.open("results/lavapipe/sibenik/compare/tradeoff-flip.samyang-7.5mm.png").convert("RGB")
height = 300
plot = plot.resize((round(plot.width * height / plot.height), height), Image.LANCZOS)
plot.save(f"{out}/tradeoff.png", optimize=True)
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
