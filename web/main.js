// The page's script: starts the wasm module on the browser's WebGPU, exposes
// `window.fisheye` ({ready, render(opts), open(opts), lensTwin, lenses}: the contract tests
// and other pages drive), and wires the controls:
// scene (built-in, picked or dropped files), lens, size, rays per pixel, scene time (a moving
// scene plays), orbiting and flying camera, the GPU time of each frame, saving the picture as PNG.
import init, { Fisheye, lenses } from "./fisheye_web.js";

const $ = (id) => document.getElementById(id);
const say = (text, bad = false) => {
  $("status").textContent = text;
  $("status").className = bad ? "bad" : "";
};

// `render`'s defaults, as `fisheye render` has them.
const DEFAULTS = { scene: "builtin:default", lens: "canon-8-15mm@8mm", size: "1024x768", spp: 16 };

const ready = (async () => {
  if (!navigator.gpu) {
    throw new Error(
      "This browser has no WebGPU (navigator.gpu is missing): use a recent Chrome, Edge or " +
        "Firefox, over https or http://localhost.",
    );
  }
  await init();
  // ?limits=default: a device with WebGPU's default limits alone, as a small one (a phone)
  // gives, to try the page as it runs there.
  const defaults = new URLSearchParams(location.search).get("limits") === "default";
  return await Fisheye.start(defaults);
})();

// The scene's name, its bytes and the files beside it, and where to fetch more (a URL's
// folder) or look for them (files dropped with it).
async function sceneOf(opts) {
  const scene = opts.scene ?? DEFAULTS.scene;
  const files = new Map();
  const extra = opts.files ?? [];
  if (typeof scene === "string" && scene.startsWith("builtin:")) {
    return { name: scene, files, extra };
  }
  if (typeof scene === "string" || scene instanceof URL) {
    const url = new URL(scene, location.href);
    const name = opts.name ?? decodeURIComponent(url.pathname.split("/").pop());
    files.set(name, await fetchBytes(url));
    return { name, files, base: url, extra };
  }
  if (scene instanceof File) {
    files.set(opts.name ?? scene.name, new Uint8Array(await scene.arrayBuffer()));
    return { name: opts.name ?? scene.name, files, extra };
  }
  if (scene instanceof ArrayBuffer || ArrayBuffer.isView(scene)) {
    if (!opts.name) throw new Error("a scene given as bytes needs its file name: opts.name");
    const bytes = scene instanceof ArrayBuffer ? new Uint8Array(scene) : viewBytes(scene);
    files.set(opts.name, bytes);
    return { name: opts.name, files, extra };
  }
  throw new Error("opts.scene: a URL, a File, an ArrayBuffer or builtin:NAME");
}

// A calibration file's name and bytes, given as a URL, a File or bytes (named by `name`).
async function calibrationOf(calib, name) {
  if (typeof calib === "string" || calib instanceof URL) {
    const url = new URL(calib, location.href);
    return { name: name ?? decodeURIComponent(url.pathname.split("/").pop()), bytes: await fetchBytes(url) };
  }
  if (calib instanceof File) return { name: name ?? calib.name, bytes: new Uint8Array(await calib.arrayBuffer()) };
  if (calib instanceof ArrayBuffer) return { name: name ?? "calibration", bytes: new Uint8Array(calib) };
  if (ArrayBuffer.isView(calib)) return { name: name ?? "calibration", bytes: viewBytes(calib) };
  throw new Error("opts.calib: a URL, a File or an ArrayBuffer");
}

// The bytes a typed array or DataView looks at (not its whole buffer).
const viewBytes = (view) => new Uint8Array(view.buffer, view.byteOffset, view.byteLength);

async function fetchBytes(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: ${response.status} ${response.statusText}`);
  return new Uint8Array(await response.arrayBuffer());
}

// A file the scene names: dropped with it, or fetched beside its URL; null if neither.
async function companion(source, name) {
  const dropped = source.extra.find((f) => f.name === name.split("/").pop());
  if (dropped) return new Uint8Array(await dropped.arrayBuffer());
  if (!source.base) return null;
  try {
    return await fetchBytes(new URL(name, source.base));
  } catch {
    return null;
  }
}

// A view of what `opts` asks (the scene loaded, its BVH built and uploaded, the kernels
// made), whose `frame(camera, progressive, time?)` renders it; `steps` is the most frames a
// progressive refinement takes, `key_span` a moving scene's first and last key times. `opts`
// are `render`'s: {scene, name?, files?, lens, size, spp, camera?, calib?, calibName?,
// calibCamera?}; a calibration file (Kalibr, OpenCV, Basalt: a URL, File or bytes) gives the
// lens and size, as `render --calib FILE`.
async function open(opts = {}) {
  const device = await ready;
  const source = await sceneOf(opts);
  const asked = {
    name: source.name,
    lens: opts.lens ?? DEFAULTS.lens,
    size: opts.size ?? DEFAULTS.size,
    spp: String(opts.spp ?? DEFAULTS.spp),
    camera: opts.camera ?? "",
    complete: false,
  };
  if (opts.calib) {
    const calibration = await calibrationOf(opts.calib, opts.calibName);
    asked.calib = calibration.bytes;
    asked.calib_name = calibration.name;
    asked.calib_camera = opts.calibCamera ?? 0;
  }
  // The loaders name the files a scene needs (MTL, textures, glTF buffers) as they read it:
  // each round finds among the dropped files, or fetches, those it missed; once none of
  // them can be had, the scene is loaded without them (with the tool's warnings or errors).
  for (;;) {
    try {
      return await device.open(source.files, asked);
    } catch (error) {
      if (asked.complete || !error.missing?.length) throw error;
      let found = 0;
      for (const name of error.missing) {
        const bytes = await companion(source, name);
        if (bytes) {
          source.files.set(name, bytes);
          found++;
        }
      }
      asked.complete = found === 0;
    }
  }
}

// Renders as `fisheye render` does (`opts.time`: its `--time`); resolves to {width, height,
// rgba, ids, gpu_ms, timed_by, wall_ms, camera, warnings}.
async function render(opts = {}) {
  const view = await open(opts);
  return await view.frame("", false, opts.time ?? 0);
}

// The WGSL lens twin against the f64 reference (compiled to wasm) at every pixel of `lens` at
// `size`, on this device: {lens, rays, max_error, max_ratio, max_error_well_conditioned,
// holds, why}.
const lensTwin = async (lens, size) => (await ready).lens_twin(lens, size);

window.fisheye = { ready, render, open, lensTwin, lenses: () => ready.then(() => lenses()) };

// ---- the page's controls

let picked = null; // {scene: File, files: File[]} from the picker or a drop
let calibration = null; // a calibration File, which gives the lens and size
let view = null; // the open view, and its progress
let pose = ""; // where the camera is, "X,Y,Z:LX,LY,LZ" ("" until the first frame)
let step = 0;
let busy = false;
let last = null;
let opening = 0; // which reopen() is the latest: an older one that finishes later is dropped
let started = performance.now(); // when a moving scene's loop began
let typed = 0; // how many times the time field changed: one changed during a frame restarts

// The scene time of the next frame: the time field's, or while it is empty a moving scene's
// loop over its keys' times; `playing` while the loop runs.
function sceneTime(current) {
  const field = $("time").value.trim();
  const span = current.key_span;
  if (field !== "" || !span) return { time: field === "" ? 0 : Number(field), playing: false };
  const [first, last] = span;
  const into = (performance.now() - started) / 1000;
  return { time: last > first ? first + (into % (last - first)) : first, playing: true };
}

function show(image) {
  const canvas = $("view");
  canvas.width = image.width;
  canvas.height = image.height;
  const data = new ImageData(new Uint8ClampedArray(image.rgba.buffer), image.width, image.height);
  canvas.getContext("2d").putImageData(data, 0, 0);
}

// Opens the view the controls ask for, then refines it frame by frame.
async function reopen() {
  const opts = {
    lens: $("lens").value.trim() || DEFAULTS.lens,
    size: $("size").value.trim() || DEFAULTS.size,
    spp: $("spp").value.trim() || DEFAULTS.spp,
  };
  if (picked) {
    opts.scene = picked.scene;
    opts.files = picked.files;
  } else {
    opts.scene = $("scene").value;
  }
  if (calibration) opts.calib = calibration;
  say("loading the scene and building its BVH…");
  view = null;
  const mine = ++opening;
  try {
    const started = performance.now();
    const opened = await open(opts);
    if (mine !== opening) return;
    view = opened;
    say(`ready in ${(performance.now() - started).toFixed(0)} ms; rendering…`);
  } catch (error) {
    if (mine === opening) say(String(error.message ?? error), true);
    return;
  }
  pose = "";
  step = 0;
  started = performance.now();
  tick();
}

// The next frame while the view has steps left at this pose and time (or a moving scene
// plays): the first at a pose or time is whole (or coarse, with adaptive sampling), each later
// one sharpens it.
async function tick() {
  const current = view;
  if (busy || !current) return;
  const { time, playing } = sceneTime(current);
  if (step >= current.steps && !playing) return;
  busy = true;
  const asked = typed;
  try {
    const frame = await current.frame(pose, true, time);
    // A frame of a view that has been replaced meanwhile is dropped.
    if (current === view) {
      last = frame;
      pose = last.camera;
      $("view").dataset.camera = pose;
      // While the scene plays each frame is the first at its time; a time typed meanwhile
      // starts again.
      const made = playing ? 1 : step + 1;
      step = asked !== typed ? 0 : made;
      show(last);
      const warned = last.warnings.length ? ` (warnings: ${last.warnings.join("; ")})` : "";
      const progress = current.steps > 1 ? `, frame ${made} of at most ${current.steps}` : "";
      const when = current.key_span ? `, scene time ${time.toFixed(2)} s` : "";
      say(
        `${last.width}×${last.height}${when}${progress}: ${last.gpu_ms.toFixed(1)} ms on the GPU ` +
          `(${last.timed_by}), ${last.wall_ms.toFixed(1)} ms from submission to pixels${warned}`,
      );
    }
  } catch (error) {
    if (current === view) {
      say(String(error.message ?? error), true);
      step = current.steps;
    }
  }
  busy = false;
  requestAnimationFrame(tick);
}

// A pose's eye and look-at point, and back.
const parsePose = (p) => p.split(":").map((t) => t.split(",").map(Number));
const poseOf = (eye, at) => `${eye.join(",")}:${at.join(",")}`;

// `point` turned about `centre` by `yaw` about the vertical (y) and `pitch` up, its distance
// kept, never over the pole.
function turned(centre, point, yaw, pitch) {
  const v = point.map((p, i) => p - centre[i]);
  const r = Math.hypot(...v);
  const y = Math.atan2(v[0], v[2]) + yaw;
  const p = Math.max(-1.5, Math.min(1.5, Math.asin(v[1] / r) + pitch));
  return [
    centre[0] + r * Math.cos(p) * Math.sin(y),
    centre[1] + r * Math.sin(p),
    centre[2] + r * Math.cos(p) * Math.cos(y),
  ];
}

// Moves to `next` (a pose) and starts refining there.
function go(next) {
  pose = next;
  step = 0;
  tick();
}

// A drag of (dx, dy) pixels: turns the eye about the look-at point (orbit), or with `look`
// the look-at point about the eye (looking around, as flying).
function drag(dx, dy, look) {
  if (!pose) return;
  const [eye, at] = parsePose(pose);
  if (look) go(poseOf(eye, turned(eye, at, -dx * 0.005, -dy * 0.005)));
  else go(poseOf(turned(at, eye, -dx * 0.01, dy * 0.01), at));
}

// Flies the eye and look-at point together `forward` steps along the view, `right` steps
// across it and `up` steps up, a step a twentieth of their distance.
function fly(forward, right, up) {
  if (!pose) return;
  const [eye, at] = parsePose(pose);
  const d = at.map((a, i) => a - eye[i]);
  const step = Math.hypot(...d) / 20;
  const f = d.map((x) => x / Math.hypot(...d));
  // Right: the view direction × y, level; none where the view is vertical.
  const level = Math.hypot(f[0], f[2]);
  const r = level > 0 ? [-f[2] / level, 0, f[0] / level] : [0, 0, 0];
  const move = [0, 1, 2].map((i) => step * (forward * f[i] + right * r[i] + (i === 1 ? up : 0)));
  go(poseOf(eye.map((e, i) => e + move[i]), at.map((a, i) => a + move[i])));
}

// Keys that fly: W/S forward and back, A/D left and right, E/Q up and down.
const FLY_KEYS = { w: [1, 0, 0], s: [-1, 0, 0], a: [0, -1, 0], d: [0, 1, 0], e: [0, 0, 1], q: [0, 0, -1] };

async function setUp() {
  let device;
  try {
    device = await ready;
    $("adapter").textContent = device.adapter || "this browser's WebGPU adapter";
  } catch (error) {
    say(String(error.message ?? error), true);
    $("render").disabled = true;
    return;
  }
  const list = $("lenses");
  for (const [spec, about] of lenses()) {
    const option = document.createElement("option");
    option.value = spec;
    option.textContent = about;
    list.append(option);
  }
  $("render").onclick = reopen;
  $("save").onclick = () => {
    $("view").toBlob((blob) => {
      const a = document.createElement("a");
      a.href = URL.createObjectURL(blob);
      a.download = "fisheye.png";
      a.click();
    }, "image/png");
  };
  const take = (files) => {
    const all = [...files];
    const scene = all.find((f) => /\.(obj|gltf|glb|toml)$/i.test(f.name));
    if (!scene) return say("drop an .obj (with its .mtl and textures), .gltf, .glb or scene .toml file", true);
    picked = { scene, files: all };
    $("picked").textContent = all.map((f) => f.name).join(", ");
    reopen();
  };
  $("file").onchange = (e) => take(e.target.files);
  $("calib").onchange = (e) => {
    calibration = e.target.files[0] ?? null;
    reopen();
  };
  $("lens").onchange = () => {
    calibration = null;
    $("calib").value = "";
    reopen();
  };
  // A time typed starts refining there; emptied, a moving scene plays again.
  $("time").oninput = () => {
    typed++;
    step = 0;
    started = performance.now();
    tick();
  };
  $("scene").onchange = () => {
    picked = null;
    $("picked").textContent = "";
    reopen();
  };
  document.body.ondragover = (e) => e.preventDefault();
  document.body.ondrop = (e) => {
    e.preventDefault();
    take(e.dataTransfer.files);
  };
  // Drag to orbit; with Shift (or the right button) to look around; keys fly. Moves made while
  // a frame is on its way are dropped (the frame brings its own pose).
  let from = null;
  $("view").onpointerdown = (e) => (from = [e.clientX, e.clientY]);
  $("view").oncontextmenu = (e) => e.preventDefault();
  window.onpointermove = (e) => {
    if (!from || busy) return;
    drag(e.clientX - from[0], e.clientY - from[1], e.shiftKey || (e.buttons & 2) !== 0);
    from = [e.clientX, e.clientY];
  };
  window.onpointerup = () => (from = null);
  window.onkeydown = (e) => {
    const keys = FLY_KEYS[e.key.toLowerCase()];
    if (!keys || busy || e.target.closest("input, select, textarea") || e.ctrlKey || e.metaKey) return;
    fly(...keys);
  };
  reopen();
}

setUp();
