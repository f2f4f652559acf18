// The web page's tests, in headless Chromium (Debian's, WebGPU on SwiftShader) driven by
// playwright-core: the page's `window.fisheye` renders scenes through lenses of every family
// (classic models, the thesis's presets, calibrated models), from the built-in scene, from
// OBJ and glTF files by URL, as bytes and as files picked in the page, and each image is
// compared with `fisheye render`'s PNG for the same arguments on lavapipe; bad input must
// give a message (a rejected promise, and the page's status line), not a dead tab.
//
// Tolerances: both drivers trace the same kernels in f32, but compile them differently
// (fused multiply-adds, transcendental approximations), so a ray grazing an edge may hit a
// different triangle in one of them, and a colour may round to the next 8-bit level. An
// image passes where at most 0.5% of its pixels differ by more than 2 levels (of 255) in
// some channel, its mean difference is under 0.1 level, and its alpha (the lens mask, from
// the lens model alone) differs in at most 0.05% of pixels. Measured: at most 0.03% of
// pixels beyond 2 levels.
import { chromium } from "playwright-core";
import { PNG } from "pngjs";
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import http from "node:http";
import os from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";

const repo = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../..");
const bin = process.env.FISHEYE_BIN ?? path.join(repo, "target/release/fisheye");
const scratch = fs.mkdtempSync(path.join(os.tmpdir(), "fisheye-web-"));

// The site at /, the repository's scenes at /scenes/.
const types = { ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm" };
const server = http.createServer((request, response) => {
  const url = decodeURIComponent(new URL(request.url, "http://localhost").pathname);
  let file = url.startsWith("/scenes/")
    ? path.join(repo, url)
    : path.join(repo, "web/dist", url);
  if (file.endsWith("/")) file += "index.html";
  fs.readFile(file, (error, data) => {
    if (error) {
      response.writeHead(404);
      response.end();
      return;
    }
    const type = types[path.extname(file)] ?? "application/octet-stream";
    response.writeHead(200, { "content-type": type });
    response.end(data);
  });
});
await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
const site = `http://localhost:${server.address().port}/`;

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: [
    "--enable-unsafe-webgpu",
    "--no-sandbox",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
  ],
});
// Every page of the tests' context gets `packed`: a result as the tests read it, the pixels
// base64-encoded across the page boundary.
const context = await browser.newContext();
await context.addInitScript(() => {
  const base64 = (bytes) => {
    let text = "";
    for (let i = 0; i < bytes.length; i += 8192) {
      text += String.fromCharCode(...bytes.subarray(i, i + 8192));
    }
    return btoa(text);
  };
  window.packed = (r, ms) => ({
    width: r.width,
    height: r.height,
    gpu_ms: r.gpu_ms,
    timed_by: r.timed_by,
    wall_ms: r.wall_ms,
    ms,
    warnings: r.warnings,
    rgba: base64(r.rgba),
    ids: r.ids ? base64(new Uint8Array(r.ids.buffer, r.ids.byteOffset, r.ids.byteLength)) : "",
  });
});
const page = await context.newPage();
const logged = [];
page.on("console", (m) => logged.push(m.text()));
page.on("pageerror", (e) => logged.push(`page error: ${e.message}`));
await page.goto(site);

let failures = 0;
const check = (ok, what) => {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures++;
};

const adapter = await page.evaluate(() => window.fisheye.ready.then((d) => d.adapter));
console.log(`WebGPU adapter: ${adapter || "(unnamed)"}`);

// The page's render of `opts` (its scene: builtin:NAME, a URL, or {bytes: PATH, name} sent
// as an ArrayBuffer) on page `on`, its pixels base64-encoded across the page boundary.
async function pageRender(opts, on = page) {
  const sent = { ...opts };
  if (opts.bytes) {
    sent.bytes = fs.readFileSync(path.join(repo, opts.bytes)).toString("base64");
  }
  return on.evaluate(async (o) => {
    if (o.bytes) {
      o.scene = Uint8Array.from(atob(o.bytes), (c) => c.charCodeAt(0)).buffer;
      delete o.bytes;
    }
    const started = performance.now();
    const r = await window.fisheye.render(o);
    return window.packed(r, performance.now() - started);
  }, sent);
}

// A .npy file of little-endian u32s (`--outputs id`), as numpy's format lays it out.
function readIds(file) {
  const b = fs.readFileSync(file);
  const v1 = b[6] === 1;
  const start = (v1 ? 10 : 12) + (v1 ? b.readUInt16LE(8) : b.readUInt32LE(8));
  const header = b.subarray(v1 ? 10 : 12, start).toString("latin1");
  if (!header.includes("'<u4'")) throw new Error(`${file}: not u32s: ${header}`);
  return new Uint32Array(b.buffer.slice(b.byteOffset + start, b.byteOffset + b.length));
}

// `fisheye render`'s PNG for the same arguments (a calibration served at /scenes/... read
// from the repository), decoded, with its ids (`--outputs id`) where sampling is uniform.
function nativeRender(scene, opts, name) {
  const out = path.join(scratch, `${name}.png`);
  const args = ["render", scene];
  if (opts.calib) {
    args.push("--calib", path.join(repo, opts.calib), "--calib-camera", String(opts.calibCamera));
  } else {
    args.push("--lens", opts.lens, "--size", opts.size);
  }
  if (opts.camera) args.push("--camera", opts.camera);
  if (opts.time !== undefined) args.push("--time", String(opts.time));
  // `1+tent`: the sampling, then the pixel filter (as `compare` labels setups).
  const [spp, filter] = String(opts.spp).split("+");
  args.push("--spp", spp, "--filter", filter ?? "box", "-o", out);
  const uniform = /^[0-9]+$/.test(spp);
  if (uniform) args.push("--outputs", "id");
  const run = spawnSync(bin, args, { encoding: "utf8" });
  if (run.status !== 0) throw new Error(`${bin} ${args.join(" ")}: ${run.stderr}`);
  const png = PNG.sync.read(fs.readFileSync(out));
  png.ids = uniform ? readIds(out.replace(/\.png$/, ".id.npy")) : null;
  return png;
}

function compare(native, web, what) {
  const a = native.data;
  const b = Buffer.from(web.rgba, "base64");
  if (native.width !== web.width || native.height !== web.height || a.length !== b.length) {
    check(false, `${what}: ${web.width}×${web.height}, native ${native.width}×${native.height}`);
    return;
  }
  const pixels = a.length / 4;
  let beyond = 0;
  let masks = 0;
  let sum = 0;
  let lit = 0;
  for (let p = 0; p < pixels; p++) {
    let most = 0;
    for (let c = 0; c < 3; c++) {
      const d = Math.abs(a[4 * p + c] - b[4 * p + c]);
      most = Math.max(most, d);
      sum += d;
    }
    if (most > 2) beyond++;
    if (a[4 * p + 3] !== b[4 * p + 3]) masks++;
    if (a[4 * p] + a[4 * p + 1] + a[4 * p + 2] > 30) lit++;
  }
  const share = beyond / pixels;
  const mean = sum / (3 * pixels);
  // Ids at the pixels' centres, where both have them: a grazing ray may hit the other
  // triangle of an edge, so as many may differ as colours may.
  let ids = "";
  let idsOk = true;
  if (native.ids && web.ids) {
    const w = Buffer.from(web.ids, "base64");
    const theirs = new Uint32Array(w.buffer, w.byteOffset, w.byteLength / 4);
    let differ = 0;
    for (let p = 0; p < pixels; p++) if (native.ids[p] !== theirs[p]) differ++;
    idsOk = theirs.length === pixels && differ / pixels <= 0.005;
    ids = `, ${differ} ids differ`;
  }
  check(
    share <= 0.005 && mean < 0.1 && masks / pixels <= 0.0005 && lit > pixels / 10 && idsOk,
    `${what}: ${(100 * share).toFixed(3)}% of pixels beyond 2 levels, mean ` +
      `${mean.toFixed(4)}, ${masks} mask pixels differ${ids}, ` +
      `${((100 * lit) / pixels).toFixed(0)}% lit; ${web.ms.toFixed(0)} ms in the page ` +
      `(${web.wall_ms.toFixed(0)} ms submission to pixels` +
      `${web.timed_by ? `, ${web.gpu_ms.toFixed(1)} ms on the GPU by ${web.timed_by}` : ""})`,
  );
}

// Scenes through lens families: presets (equidistant, equisolid), classic models, calibrated
// models; supersampled and not; the built-in scene, a bare OBJ with its MTL fetched beside
// its URL, a GLB sent as bytes.
const cases = [
  { scene: "builtin:default", lens: "canon-8-15mm@8mm", size: "256x192", spp: 1 },
  { scene: "builtin:default", lens: "samyang-7.5mm", size: "256x192", spp: 4 },
  { scene: "builtin:default", lens: "canon-8-15mm@8mm", size: "256x192", spp: "1+tent" },
  {
    scene: "/scenes/cornell_box/CornellBox-Original.obj",
    lens: "stereographic:f=0.5,fov=180",
    size: "200x150",
    spp: 1,
  },
  {
    bytes: "scenes/gltf/pavilion.glb",
    name: "pavilion.glb",
    lens: "kb:fx=62,fy=62,cx=96,cy=96,k1=0.0034824,k2=0.00071503,k3=-0.0020532,k4=0.00020294",
    size: "192x192",
    spp: 1,
  },
  { scene: "builtin:grid", lens: "orthographic:f=0.6,fov=180", size: "160x120", spp: 1 },
  {
    scene: "builtin:default",
    lens: "ds:fx=50,fy=50,cx=80,cy=60,xi=-0.18,alpha=0.59",
    size: "160x120",
    spp: 1,
  },
  // A scene file whose box slides and turns over a second, at 0.8 s (`render --time 0.8`).
  { scene: "/scenes/dataset/sliding.toml", lens: "equidistant:f=0.5,fov=180", size: "160x120", spp: 1, time: 0.8 },
];
const timings = [];
for (const [k, c] of cases.entries()) {
  const file = c.bytes ?? (c.scene.startsWith("/") ? c.scene.slice(1) : null);
  const scene = file ? path.join(repo, file) : c.scene;
  const at = c.time === undefined ? "" : `, time ${c.time} s`;
  const what = `${c.bytes ?? c.scene} through ${c.lens.split(":")[0]} at ${c.size}, spp ${c.spp}${at}`;
  try {
    const native = nativeRender(scene, c, `case${k}`);
    const web = await pageRender(c);
    compare(native, web, what);
    timings.push(web);
  } catch (error) {
    check(false, `${what}: ${error.message ?? error}`);
  }
}
// SwiftShader has timestamp queries: each frame's GPU time is theirs, more than nothing and
// no more than the time from submission to its pixels (Chromium quantises timestamps to
// 0.1 ms, hence the margin).
check(
  timings.length === cases.length &&
    timings.every((t) => t.timed_by === "timestamps" && t.gpu_ms > 0 && t.gpu_ms <= t.wall_ms + 0.1),
  `frames timed by GPU timestamps: ${timings.map((t) => `${t.gpu_ms.toFixed(1)} of ${t.wall_ms.toFixed(0)} ms`).join(", ")}`,
);

// The lens twins in the page: the WGSL lens code on SwiftShader against the f64 reference
// compiled to wasm, at every pixel, within `fisheye_rt::lens::twin`'s bounds (those
// tests/lens_gpu.rs holds lavapipe to): every classic model, every preset, every calibrated
// model's example.
const twins = await page.evaluate(() => window.fisheye.lenses());
const twinSpecs = [
  "rectilinear:f=0.5",
  "stereographic:f=0.3",
  "equidistant:f=0.3",
  "equisolid:f=0.45",
  "orthographic:f=0.66",
  "general:f=0.5,k1=0.5,k2=0.5",
  "general:f=0.5,k1=0.5,k2=-0.5",
  ...twins.map(([spec]) => spec).filter((spec) => !spec.includes(":") || spec.includes("fx=") || spec.includes("cx=")),
];
for (const spec of twinSpecs) {
  const size = spec.startsWith("radtan") ? "752x480" : spec.includes("cx=") ? "512x512" : "256x192";
  const twin = await page
    .evaluate(([l, s]) => window.fisheye.lensTwin(l, s), [spec, size])
    .catch((e) => ({ holds: false, why: String(e.message ?? e), rays: 0 }));
  check(
    twin.holds && twin.rays > 1000,
    `lens twin ${spec.split(":")[0]} at ${size}: ${twin.rays} rays, max error ` +
      `${twin.max_error?.toExponential(2)} rad, ${twin.max_ratio?.toFixed(2)} of the bound ${twin.why}`,
  );
}

// Files dropped or picked in the page: the Cornell box's OBJ and MTL as `File`s through
// `render` (as a drop hands them over), and through the page's file input, its canvas read
// back, each as `fisheye render` makes it.
{
  const lens = "equisolid:f=0.5,fov=180";
  const obj = "scenes/cornell_box/CornellBox-Original.obj";
  const files = [obj, obj.replace(".obj", ".mtl")].map((f) => ({
    name: path.basename(f),
    base64: fs.readFileSync(path.join(repo, f)).toString("base64"),
  }));
  const native = nativeRender(path.join(repo, obj), { lens, size: "200x150", spp: 1 }, "dropped");
  const dropped = await page.evaluate(
    async ([files, lens]) => {
      const made = files.map(
        (f) => new File([Uint8Array.from(atob(f.base64), (c) => c.charCodeAt(0))], f.name),
      );
      const started = performance.now();
      const r = await window.fisheye.render({ scene: made[0], files: made, lens, size: "200x150", spp: 1 });
      return window.packed(r, performance.now() - started);
    },
    [files, lens],
  );
  compare(native, dropped, `${obj} and its MTL as Files through ${lens.split(":")[0]}`);
  check(dropped.warnings.length === 0, `the dropped MTL was read (warnings: ${dropped.warnings})`);
  const picker = await context.newPage();
  await picker.goto(site);
  await picker.waitForFunction(() => /submission/.test(document.getElementById("status").textContent), null, {
    timeout: 300000,
  });
  await picker.fill("#size", "200x150");
  await picker.fill("#spp", "1");
  await picker.fill("#lens", lens);
  await picker.setInputFiles("#file", [obj, obj.replace(".obj", ".mtl")].map((f) => path.join(repo, f)));
  await picker
    .waitForFunction(() => /^200×150: .*submission/.test(document.getElementById("status").textContent), null, {
      timeout: 120000,
    })
    .catch(async (e) => {
      throw new Error(`the page said: ${await picker.textContent("#status")} (${e.message})`);
    });
  const canvas = await picker.evaluate(() => {
    const c = document.getElementById("view");
    const r = { width: c.width, height: c.height, rgba: c.getContext("2d").getImageData(0, 0, c.width, c.height).data, warnings: [] };
    return window.packed({ ...r, rgba: new Uint8Array(r.rgba.buffer), wall_ms: 0 }, 0);
  });
  compare(native, canvas, `${obj} and its MTL picked in the page, its canvas`);

  // Flying, in the default room (no headlight, which `--camera` would place at the new eye):
  // W moves the eye and look-at point a twentieth of their distance along the view, D as far
  // to the right (level), E as far up; a Shift-drag turns the view about the eye, keeping it
  // and the distance. Each move renders a frame at the new pose (the canvas, read back at the
  // end, is `fisheye render --camera` there).
  const pose = () => picker.evaluate(() => document.getElementById("view").dataset.camera);
  const after = async (move) => {
    const before = await pose();
    await move();
    await picker
      .waitForFunction((p) => document.getElementById("view").dataset.camera !== p, before, {
        timeout: 120000,
      })
      .catch(async (e) => {
        throw new Error(`the camera stayed at ${before}; the page said: ${await picker.textContent("#status")} (${e.message})`);
      });
    return [before, await pose()].map((p) => p.split(":").map((t) => t.split(",").map(Number)));
  };
  const sub = (a, b) => a.map((x, i) => x - b[i]);
  const near = (a, b) => Math.hypot(...sub(a, b)) < 1e-9 * (1 + Math.hypot(...b));
  const flew = async (key, direction) => {
    const [[eye0, at0], [eye1, at1]] = await after(() => picker.keyboard.press(key));
    const d = sub(at0, eye0);
    const step = Math.hypot(...d) / 20;
    const wanted = direction(d.map((x) => x / Math.hypot(...d))).map((x) => x * step);
    return near(sub(eye1, eye0), wanted) && near(sub(at1, at0), wanted);
  };
  // Keys typed into the controls are theirs: leave them first (leaving a changed one
  // re-renders, before the scene's change below).
  await picker.evaluate(() => document.activeElement.blur());
  await after(() => picker.selectOption("#scene", "builtin:default"));
  const forward = await flew("w", (f) => f);
  const right = await flew("d", (f) => {
    const level = Math.hypot(f[0], f[2]);
    return [-f[2] / level, 0, f[0] / level];
  });
  const up = await flew("e", () => [0, 1, 0]);
  const box = await picker.locator("#view").boundingBox();
  const [[eye0, at0], [eye1, at1]] = await after(async () => {
    await picker.keyboard.down("Shift");
    await picker.mouse.move(box.x + 50, box.y + 50);
    await picker.mouse.down();
    await picker.mouse.move(box.x + 80, box.y + 60);
    await picker.mouse.up();
    await picker.keyboard.up("Shift");
  });
  const distance = (a, b) => Math.hypot(...sub(a, b));
  const looked =
    near(eye1, eye0) && !near(at1, at0) && Math.abs(distance(at1, eye1) - distance(at0, eye0)) < 1e-9;
  check(forward && right && up && looked, `W, D and E fly the camera by a twentieth of its distance (${forward}, ${right}, ${up}); Shift-drag turns it about the eye (${looked})`);
  await picker.waitForFunction(() => /^200×150: .*submission/.test(document.getElementById("status").textContent));
  const flown = await pose();
  const seen = await picker.evaluate(() => {
    const c = document.getElementById("view");
    const r = { width: c.width, height: c.height, rgba: c.getContext("2d").getImageData(0, 0, c.width, c.height).data, warnings: [] };
    return window.packed({ ...r, rgba: new Uint8Array(r.rgba.buffer), wall_ms: 0 }, 0);
  });
  const there = nativeRender("builtin:default", { lens, size: "200x150", spp: 1, camera: flown }, "flown");
  compare(there, seen, `the canvas after flying, against fisheye render --camera ${flown}`);

  // A scene file picked in the page plays: while the time field is empty the status line's
  // scene time moves from frame to frame; a time typed there holds it.
  await picker.setInputFiles("#file", path.join(repo, "scenes/dataset/sliding.toml"));
  const timeSaid = (not) =>
    picker
      .waitForFunction(
        (n) => {
          const m = /scene time ([0-9.]+) s/.exec(document.getElementById("status").textContent);
          return m && m[1] !== n ? m[1] : null;
        },
        not,
        { timeout: 120000 },
      )
      .then((h) => h.jsonValue());
  const playing = [await timeSaid(null)];
  playing.push(await timeSaid(playing[0]));
  await picker.fill("#time", "0.25");
  const held = await picker
    .waitForFunction(() => /scene time 0\.25 s/.test(document.getElementById("status").textContent), null, {
      timeout: 120000,
    })
    .then(() => true, () => false);
  check(
    playing[0] !== playing[1] && held,
    `a picked scene file plays (scene time ${playing.join(" s, then ")} s); a time typed holds it (${held})`,
  );
  await picker.close();
}

// A calibration file (a Kalibr rig's camera 1, by URL) gives the lens and size, as
// `render --calib FILE --calib-camera 1`.
{
  const opts = { scene: "builtin:default", calib: "/scenes/dataset/surround-rig.yaml", calibCamera: 1, spp: 1 };
  const what = "builtin:default through surround-rig.yaml's camera 1 (Kalibr), spp 1";
  try {
    const native = nativeRender("builtin:default", { ...opts, calib: opts.calib.slice(1) }, "calib");
    compare(native, await pageRender(opts), what);
  } catch (error) {
    check(false, `${what}: ${error.message ?? error}`);
  }
}

// Progressive refinement: a view with adaptive sampling shows the coarse frame first and
// sharpens it frame by frame at the same pose, ending with the whole adaptive frame bit for
// bit (as `fisheye render --spp auto` makes it natively); a new pose starts again.
const progressive = await page.evaluate(async () => {
  const opts = { scene: "builtin:default", lens: "samyang-7.5mm", size: "128x96", spp: "auto" };
  const view = await window.fisheye.open(opts);
  const whole = await (await window.fisheye.open(opts)).frame("", false);
  const same = (a, b) => a.rgba.length === b.rgba.length && a.rgba.every((v, i) => v === b.rgba[i]);
  const frames = [];
  for (let k = 0; k < view.steps; k++) frames.push(await view.frame("", true));
  const moved = await view.frame("0,1.5,2:0,1.2,-3", true);
  const back = await view.frame("", true);
  return {
    steps: view.steps,
    coarseDiffers: !same(frames[0], whole),
    lastIsWhole: same(frames[frames.length - 1], whole),
    firstSameAsWhole: frames.findIndex((f) => same(f, whole)),
    movedDiffers: !same(moved, whole),
    restarted: same(back, frames[0]),
  };
});
check(
  progressive.coarseDiffers && progressive.lastIsWhole && progressive.movedDiffers && progressive.restarted,
  `progressive refinement: ${progressive.steps} frames at most, the first coarse, the whole ` +
    `frame bit for bit from frame ${progressive.firstSameAsWhole + 1}; a move restarts it`,
);
compare(
  nativeRender("builtin:default", { lens: "samyang-7.5mm", size: "128x96", spp: "auto" }, "auto"),
  await pageRender({ scene: "builtin:default", lens: "samyang-7.5mm", size: "128x96", spp: "auto" }),
  "builtin:default through samyang-7.5mm at 128x96, spp auto (adaptive)",
);

// A moving scene: a view's `key_span` is its keys' first and last times (none where nothing
// moves); at one pose a new time starts progressive refinement again (the frame at 0.8 s after
// frames at 0.2 s is a fresh view's first at 0.8 s, and not the one at 0.2 s); a time that is
// not a number is refused.
const moving = await page.evaluate(async () => {
  const opts = { scene: "/scenes/dataset/sliding.toml", lens: "equidistant:f=0.5,fov=180", size: "160x120", spp: 1 };
  const view = await window.fisheye.open(opts);
  const still = await window.fisheye.open({ scene: "builtin:grid", size: "32x24", spp: 1 });
  const same = (a, b) => a.rgba.length === b.rgba.length && a.rgba.every((v, i) => v === b.rgba[i]);
  const early = await view.frame("", true, 0.2);
  await view.frame("", true, 0.2);
  const late = await view.frame("", true, 0.8);
  const fresh = await (await window.fisheye.open(opts)).frame("", true, 0.8);
  const refused = await view.frame("", true, NaN).then(() => "rendered", (e) => String(e.message ?? e));
  return {
    span: Array.from(view.key_span ?? []),
    stillSpan: still.key_span ?? null,
    restarted: same(late, fresh) && !same(late, early),
    refused,
  };
});
check(
  moving.span.join() === "0,1" && moving.stillSpan === null && moving.restarted && /time NaN/.test(moving.refused),
  `a moving scene: keys from ${moving.span.join(" to ")} s (a still one: ${moving.stillSpan}), a new ` +
    `time restarts its frames (${moving.restarted}), a bad one is refused: ${moving.refused}`,
);

// A device with WebGPU's default limits alone (?limits=default), 8 storage buffers a stage as
// on many phones: the tracer and adaptive sampling work within them, as natively.
{
  const small = await context.newPage();
  await small.goto(`${site}?limits=default`);
  const buffers = await small.evaluate(() => window.fisheye.ready.then((d) => d.storage_buffers));
  check(buffers === 8, `?limits=default gives a device of WebGPU's default 8 storage buffers (${buffers})`);
  const opts = { lens: "samyang-7.5mm", size: "128x96", spp: "auto" };
  compare(
    nativeRender("builtin:default", opts, "auto"),
    await pageRender({ scene: "builtin:default", ...opts }, small),
    "builtin:default through samyang-7.5mm at 128x96, spp auto (adaptive), on 8 storage buffers",
  );
  await small.close();
}

// The MTL beside the OBJ was fetched: the Cornell box's red wall is red, as natively (the
// comparison above); and no warning said a file was missing.
const cornell = await pageRender(cases.find((c) => c.scene?.includes("CornellBox")));
check(cornell.warnings.length === 0, `the OBJ's MTL was fetched (warnings: ${cornell.warnings})`);

// Bad input: a broken OBJ as bytes rejects with the file and line; picked in the page, its
// status line says so and the page still renders afterwards.
const broken = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 nine\n";
const refused = await page.evaluate(async (text) => {
  try {
    await window.fisheye.render({ scene: new TextEncoder().encode(text).buffer, name: "broken.obj" });
    return "rendered";
  } catch (error) {
    return String(error.message ?? error);
  }
}, broken);
check(
  refused.includes("broken.obj") && refused.includes("line 4") && refused.includes("nine"),
  `a broken OBJ is refused with its file and line: ${refused}`,
);
await page.setInputFiles("#file", {
  name: "broken.obj",
  mimeType: "text/plain",
  buffer: Buffer.from(broken),
});
await page.waitForFunction(() => document.getElementById("status").className === "bad", null, {
  timeout: 60000,
});
const status = await page.textContent("#status");
check(status.includes("line 4"), `the page says why: ${status}`);
const refusedLens = await page.evaluate(() =>
  window.fisheye.render({ lens: "fisheye-from-nowhere", size: "64x48" }).then(
    () => "rendered",
    (e) => String(e.message ?? e),
  ),
);
check(refusedLens.includes("fisheye-from-nowhere"), `an unknown lens is named: ${refusedLens}`);
const after = await pageRender({ scene: "builtin:default", lens: "canon-8-15mm@8mm", size: "64x48", spp: 1 });
check(after.width === 64 && after.height === 48, "the page renders after bad input");

// A browser without WebGPU (Chromium without --enable-unsafe-webgpu, headless on Linux):
// `ready` rejects with a message, which the page shows, rather than a dead page.
{
  const plain = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
    args: ["--no-sandbox", "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync"],
  });
  const without = await plain.newPage();
  await without.goto(site);
  const said = await without.evaluate(() =>
    window.fisheye.ready.then(
      () => "ready",
      (e) => String(e.message ?? e),
    ),
  );
  await without.waitForFunction(() => document.getElementById("status").className === "bad", null, {
    timeout: 60000,
  });
  const shown = await without.textContent("#status");
  check(said !== "ready" && /WebGPU/.test(said) && shown === said, `without WebGPU the page says: ${said}`);
  await plain.close();
}

// With TIMINGS=N, each of the book's timed frames is rendered N times and the medians of all
// but the first printed: submission to pixels, and GPU time.
if (process.env.TIMINGS) {
  const timed = [
    { scene: "builtin:default", lens: "samyang-7.5mm", size: "256x192", spp: 4 },
    { scene: "builtin:default", lens: "canon-8-15mm@8mm", size: "1024x768", spp: 1 },
  ];
  const median = (v) => v.slice(1).sort((a, b) => a - b)[Math.floor((v.length - 1) / 2)];
  for (const opts of timed) {
    const frames = [];
    for (let i = 0; i < Number(process.env.TIMINGS); i++) frames.push(await pageRender(opts));
    const wall = frames.map((f) => f.wall_ms);
    const gpu = frames.map((f) => f.gpu_ms);
    console.log(
      `timing ${opts.lens} ${opts.size} spp ${opts.spp}: first ${wall[0].toFixed(0)} ms, medians of ` +
        `the rest ${median(wall).toFixed(0)} ms submission to pixels, ${median(gpu).toFixed(1)} ms on ` +
        `the GPU (${frames[0].timed_by})`,
    );
  }
}

// With SCREENSHOT=FILE, the page as a user sees it after rendering the default room (the
// README's picture).
if (process.env.SCREENSHOT) {
  const fresh = await browser.newPage({ viewport: { width: 1000, height: 790 } });
  await fresh.goto(site);
  // The page renders the default room as it opens; then at the picture's size.
  const rendered = () => /submission/.test(document.getElementById("status").textContent);
  await fresh.waitForFunction(rendered, null, { timeout: 300000 });
  await fresh.fill("#size", "800x560");
  await fresh.fill("#spp", "4");
  await fresh.click("#render");
  await fresh.waitForFunction(() => document.getElementById("status").textContent.startsWith("800×560:"), null, {
    timeout: 300000,
  });
  await fresh.screenshot({ path: process.env.SCREENSHOT });
  console.log(`wrote ${process.env.SCREENSHOT}`);
}

await browser.close();
server.close();
fs.rmSync(scratch, { recursive: true, force: true });
if (failures > 0) {
  console.log(`${failures} web page check(s) failed; the page's console said:`);
  for (const line of logged.slice(-20)) console.log(`  ${line.slice(0, 400)}`);
  process.exit(1);
}
console.log("web page: every check passed");
