"""Tests of the `fisheye_rt` Python package (built by maturin; `.ci/test` installs and runs
them). Lens models against other implementations (OpenCV's cv::fisheye, a double sphere in
numpy written here from Usenko et al. 2018), renders against the `fisheye` command's files bit
for bit, calibration files against OpenCV's own reader, and bad input as exceptions."""

import ast
import inspect
import os
import re
import subprocess
import threading
import time
from pathlib import Path

import cv2
import numpy as np
import pytest
from PIL import Image

import fisheye_rt as fr

ROOT = Path(__file__).resolve().parents[2]
# The command-line tool, built by `cargo test --release` before these run.
FISHEYE = os.environ.get("FISHEYE_BIN", str(ROOT / "target" / "release" / "fisheye"))


def directions(n, max_theta, seed=1):
    """`n` unit directions, uniform in solid angle up to `max_theta` from the optical axis."""
    rng = np.random.default_rng(seed)
    z = rng.uniform(np.cos(max_theta), 1.0, n)
    phi = rng.uniform(0.0, 2 * np.pi, n)
    s = np.sqrt(1 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


def angle(a, b):
    """Angles in radians between rows of unit vectors, precise for small angles."""
    return 2 * np.arcsin(np.clip(np.linalg.norm(a - b, axis=1) / 2, 0, 1))


KB = dict(fx=300.5, fy=301.25, cx=319.7, cy=241.3, k=[0.031, -0.0082, 0.0021, -0.00027])


def test_kannala_brandt_matches_cv2_fisheye():
    """The f64 reference projects where cv2.fisheye.projectPoints does, to 1e-9 px, and
    unprojects cv2's pixels back to the directions, to 1e-9 rad (OpenCV pixel convention)."""
    k = KB
    spec = "kb:fx={fx},fy={fy},cx={cx},cy={cy},k1={},k2={},k3={},k4={}".format(*k["k"], **k)
    lens = fr.Lens.from_spec(spec, size=(640, 480))
    d = directions(2000, np.radians(85))
    K = np.array([[k["fx"], 0, k["cx"]], [0, k["fy"], k["cy"]], [0, 0, 1.0]])
    cv_pixels, _ = cv2.fisheye.projectPoints(
        d[:, None, :], np.zeros(3), np.zeros(3), K, np.array(k["k"])
    )
    cv_pixels = cv_pixels[:, 0, :]
    inside = (
        (cv_pixels[:, 0] >= -0.5)
        & (cv_pixels[:, 0] <= 639.5)
        & (cv_pixels[:, 1] >= -0.5)
        & (cv_pixels[:, 1] <= 479.5)
    )
    assert inside.sum() > 1000
    ours = lens.project(d, pixel_origin="opencv")
    assert np.all(np.isnan(ours[~inside]))
    assert np.max(np.abs(ours[inside] - cv_pixels[inside])) < 1e-9
    back = lens.unproject(cv_pixels[inside], pixel_origin="opencv")
    assert np.max(angle(back, d[inside])) < 1e-9
    # The project's own convention is half a pixel off OpenCV's.
    corner = lens.project(d[inside], pixel_origin="corner")
    assert np.max(np.abs(corner - cv_pixels[inside] - 0.5)) < 1e-9


def ds_project(d, fx, fy, cx, cy, xi, alpha):
    """Double sphere projection (Usenko, Demmel, Cremers, 3DV 2018, eq. 40-45), OpenCV pixels."""
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    d1 = np.sqrt(x * x + y * y + z * z)
    zx = xi * d1 + z
    d2 = np.sqrt(x * x + y * y + zx * zx)
    den = alpha * d2 + (1 - alpha) * zx
    return np.stack([fx * x / den + cx, fy * y / den + cy], axis=1)


def ds_unproject(p, fx, fy, cx, cy, xi, alpha):
    """Double sphere unprojection (same paper, eq. 46-51): unit directions."""
    mx, my = (p[:, 0] - cx) / fx, (p[:, 1] - cy) / fy
    r2 = mx * mx + my * my
    mz = (1 - alpha * alpha * r2) / (alpha * np.sqrt(1 - (2 * alpha - 1) * r2) + 1 - alpha)
    k = (mz * xi + np.sqrt(mz * mz + (1 - xi * xi) * r2)) / (mz * mz + r2)
    v = np.stack([k * mx, k * my, k * mz - xi], axis=1)
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_double_sphere_matches_an_independent_numpy_model():
    """Both directions of the double sphere against the paper's closed forms, to 1e-9."""
    p = dict(fx=158.28, fy=158.24, cx=254.9, cy=256.9, xi=-0.18, alpha=0.59)
    lens = fr.Lens.from_spec("ds:" + ",".join(f"{k}={v}" for k, v in p.items()), size=(512, 512))
    d = directions(2000, np.radians(95), seed=2)
    expected = ds_project(d, **p)
    ours = lens.project(d, pixel_origin="opencv")
    keep = ~np.isnan(ours[:, 0])
    assert keep.sum() > 1000
    assert np.max(np.abs(ours[keep] - expected[keep])) < 1e-9
    back = lens.unproject(expected[keep], pixel_origin="opencv")
    assert np.max(angle(back, ds_unproject(expected[keep], **p))) < 1e-9
    assert np.max(angle(back, d[keep])) < 1e-9


def test_arrays_keep_their_shape_and_mark_missing_rays_with_nan():
    """Any leading shape comes back; points outside the image or field are NaN rows; lists
    and integer arrays are taken; the GPU's f32 answers agree with the f64 reference."""
    lens = fr.Lens.from_spec("samyang-7.5mm", size=(64, 48))
    grid = np.stack(np.meshgrid(np.arange(64) + 0.5, np.arange(48) + 0.5), axis=-1)
    dirs = lens.unproject(grid)
    assert dirs.shape == (48, 64, 3)
    one = lens.unproject([32, 24])
    assert one.shape == (3,)
    assert np.allclose(one, [0, 0, 1])
    outside = lens.unproject([[-5, -5], [70, 10]])
    assert np.all(np.isnan(outside))
    behind = lens.project([[0, 0, -1]])
    assert np.all(np.isnan(behind))
    gpu = lens.unproject(grid, gpu=True)
    both = ~np.isnan(dirs[..., 0]) & ~np.isnan(gpu[..., 0])
    assert both.sum() > 0.9 * (~np.isnan(dirs[..., 0])).sum()
    assert np.max(angle(gpu[both], dirs[both])) < 1e-5


def fisheye(*args):
    return subprocess.run([FISHEYE, *args], check=True, capture_output=True, text=True)


def test_a_render_equals_the_commands_files_bit_for_bit(tmp_path):
    """`Renderer.render` returns the arrays `fisheye render --outputs` writes, bit for bit,
    and the PNG's pixels as "srgb"."""
    out = tmp_path / "view.png"
    fisheye(
        "render", "builtin:default", "--lens", "samyang-7.5mm", "--size", "96x72", "--spp",
        "4", "--outputs", "range,normal,id,direction,mask,depth,point", "-o", str(out),
    )
    renderer = fr.Renderer(fr.Scene.load("builtin:default"))
    lens = fr.Lens.from_spec("samyang-7.5mm", size=(96, 72))
    names = ["srgb", "range", "normal", "id", "direction", "mask", "depth", "point"]
    arrays = renderer.render(lens, spp=4, outputs=names)
    for name in names[1:]:
        written = np.load(tmp_path / f"view.{name}.npy")
        assert arrays[name].dtype == written.dtype, name
        assert arrays[name].shape == written.shape, name
        assert arrays[name].tobytes() == written.tobytes(), name
    png = np.asarray(Image.open(out).convert("RGBA"))
    assert np.array_equal(arrays["srgb"], png)
    # The point is the hit in the camera's frame: its length the range, its z the depth, and
    # its direction the lens's own ray for the pixel (projected back to the pixel's centre).
    point, rng = arrays["point"], arrays["range"]
    hit = rng > 0
    assert hit.sum() > 1000
    assert np.array_equal(arrays["depth"], point[..., 2])
    assert np.allclose(np.linalg.norm(point, axis=2), rng, rtol=1e-6, atol=0)
    rows, cols = np.nonzero(hit)
    pixels = lens.project(point[hit].astype(np.float64))
    assert np.max(np.abs(pixels - np.stack([cols + 0.5, rows + 0.5], axis=1))) < 1e-3


def test_moving_objects_render_at_a_time_as_the_command_does(tmp_path):
    """`render(time=...)` places keyed meshes where `fisheye render --time` does, bit for bit,
    from one upload (the meshes' BVHs built once), and they move between times; the scene's
    `key_span` is its keys' first and last times (None for a scene that does not move)."""
    scene = str(ROOT / "scenes" / "dataset" / "sliding.toml")
    loaded = fr.Scene.load(scene)
    assert loaded.key_span == (0.0, 1.0)
    assert fr.Scene.load("builtin:default").key_span is None
    renderer = fr.Renderer(loaded)
    lens = fr.Lens.from_spec("rectilinear:f=1.2", size=(48, 36))
    ids = {}
    for time in ("0.25", "0.75"):
        out = tmp_path / f"at-{time}.png"
        fisheye(
            "render", scene, "--lens", "rectilinear:f=1.2", "--size", "48x36", "--spp", "1",
            "--time", time, "--outputs", "id,range", "-o", str(out),
        )
        arrays = renderer.render(lens, spp=1, outputs=["id", "range"], time=float(time))
        for name in ("id", "range"):
            written = np.load(tmp_path / f"at-{time}.{name}.npy")
            assert arrays[name].tobytes() == written.tobytes(), (time, name)
        ids[time] = arrays["id"]
    assert (ids["0.25"] != ids["0.75"]).sum() > 20


def test_adaptive_sampling_equals_the_commands_and_keeps_exact_ground_truth(tmp_path):
    """spp="auto:..." renders what `fisheye render --spp auto:...` writes, bit for bit; its
    ids are uniform sampling's (never interpolated); at threshold 0 it is uniform sampling at
    its most rays exactly; and it spends fewer rays than that, so it differs somewhere. Its
    "spp" map is the command's spp.npy, and adds up to the rays it says it traced; uniform
    sampling's is its count at every pixel the lens covers, and at threshold 0 each pixel
    takes its centre's ray and then uniform sampling's."""
    out = tmp_path / "auto.png"
    said = fisheye(
        "render", "builtin:default", "--lens", "samyang-7.5mm", "--size", "96x72", "--spp",
        "auto:0.05:4", "--outputs", "range,id,spp", "-o", str(out),
    ).stdout
    renderer = fr.Renderer(fr.Scene.load("builtin:default"))
    lens = fr.Lens.from_spec("samyang-7.5mm", size=(96, 72))
    auto = renderer.render(
        lens, spp="auto:0.05:4", outputs=["srgb", "colour", "range", "id", "spp"]
    )
    for name in ["range", "id", "spp"]:
        written = np.load(tmp_path / f"auto.{name}.npy")
        assert auto[name].dtype == written.dtype and auto[name].shape == written.shape, name
        assert auto[name].tobytes() == written.tobytes(), name
    assert np.array_equal(auto["srgb"], np.asarray(Image.open(out).convert("RGBA")))
    traced = int(re.search(r"(\d+) rays for their colour", said).group(1))
    assert auto["spp"].dtype == np.uint32 and auto["spp"].shape == (72, 96)
    assert int(auto["spp"].sum()) == traced
    assert (auto["spp"] == 0).any() and auto["spp"].max() == 5, np.unique(auto["spp"])
    uniform = renderer.render(lens, spp=4, outputs=["colour", "id", "spp"])
    assert np.array_equal(auto["id"], uniform["id"])
    assert not np.array_equal(auto["colour"], uniform["colour"])
    covered = uniform["colour"][..., 3] > 0
    assert covered.all()  # the Samyang's image fills the frame
    assert np.array_equal(uniform["spp"], np.where(covered, 4, 0).astype(np.uint32))
    exact = renderer.render(lens, spp="auto:0:4", outputs=["colour", "spp"])
    assert exact["colour"].tobytes() == uniform["colour"].tobytes()
    assert np.array_equal(exact["spp"], uniform["spp"] + 1)


def test_the_tent_filter_is_the_commands(tmp_path):
    """filter="tent" renders what `fisheye render --filter tent` writes, bit for bit, and
    changes a one-ray image's colour but not its ground truth; at more rays a pixel it warns
    and keeps the box."""
    out = tmp_path / "tent.png"
    fisheye(
        "render", "builtin:default", "--lens", "samyang-7.5mm", "--size", "96x72", "--spp",
        "auto:0.1:1", "--filter", "tent", "--outputs", "id", "-o", str(out),
    )
    renderer = fr.Renderer(fr.Scene.load("builtin:default"))
    lens = fr.Lens.from_spec("samyang-7.5mm", size=(96, 72))
    tent = renderer.render(lens, spp="auto:0.1:1", filter="tent", outputs=["srgb", "id"])
    assert np.array_equal(tent["srgb"], np.asarray(Image.open(out).convert("RGBA")))
    assert tent["id"].tobytes() == np.load(tmp_path / "tent.id.npy").tobytes()
    boxed = renderer.render(lens, spp="auto:0.1:1", outputs=["srgb", "id"])
    assert np.array_equal(boxed["id"], tent["id"])
    assert not np.array_equal(boxed["srgb"], tent["srgb"])
    # With more rays than one a pixel the tent changes nothing, and a warning says so, as the
    # command's note does; the image is the box's.
    with pytest.warns(UserWarning, match="each pixel keeps its rays' mean"):
        many = renderer.render(lens, spp=4, filter="tent", outputs=["srgb"])
    assert np.array_equal(many["srgb"], renderer.render(lens, spp=4, outputs=["srgb"])["srgb"])


def test_a_prescription_is_a_lens_as_the_command_line_has_it():
    """Lens.from_spec takes a lens prescription (mapping by its chief rays, fitted as
    Kannala-Brandt at the size): directions land where `fisheye lens project` puts them, to
    print precision."""
    spec = f"prescription:{ROOT / 'lenses' / 'fisheye-10mm.dat'},fstop=5.6"
    lens = fr.Lens.from_spec(spec, size=(320, 240))
    dirs = np.array([[0.0, 0.0, 1.0], [0.5, 0.2, 0.8], [-0.9, 0.1, 0.3]])
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    pixels = lens.project(dirs)
    out = subprocess.run(
        [FISHEYE, "lens", "project", "--lens", spec, "--size", "320x240"],
        input="\n".join(" ".join(repr(float(v)) for v in d) for d in dirs),
        check=True, capture_output=True, text=True,
    ).stdout
    expected = np.array([[float(v) for v in line.split()] for line in out.splitlines()])
    assert np.allclose(pixels, expected, atol=1e-6)
    assert np.allclose(pixels[0], [160.0, 120.0])


def test_a_prescription_renders_through_its_glass_as_the_command_does(tmp_path):
    """Rendering through a prescription traces its glass, as `fisheye render` does (the
    PNG's pixels, bit for bit); with rays=fit it renders the fitted model instead, whose
    image the glass's vignetting darkens toward the edge of the circle."""
    spec = f"prescription:{ROOT / 'lenses' / 'fisheye-10mm.dat'}"
    out = tmp_path / "glass.png"
    fisheye("render", "builtin:default", "--lens", spec, "--size", "64x48", "--spp", "16",
            "-o", str(out))
    renderer = fr.Renderer(fr.Scene.load("builtin:default"))
    glass = renderer.render(fr.Lens.from_spec(spec, size=(64, 48)), spp=16,
                            outputs=["srgb", "colour"])
    assert np.array_equal(glass["srgb"], np.asarray(Image.open(out).convert("RGBA")))
    fit = renderer.render(fr.Lens.from_spec(spec + ",rays=fit", size=(64, 48)), spp=16,
                          outputs=["colour"])
    ring = lambda c, lo, hi: np.nanmean(c[..., :3][ring_mask(lo, hi)])
    # The centre alike (within the samples' noise), the rim of the circle far darker.
    assert abs(ring(glass["colour"], 0, 6) / ring(fit["colour"], 0, 6) - 1) < 0.1
    assert ring(glass["colour"], 26, 31) < 0.7 * ring(fit["colour"], 26, 31)


def ring_mask(lo, hi, size=(64, 48)):
    y, x = np.mgrid[0:size[1], 0:size[0]]
    r = np.hypot(x + 0.5 - size[0] / 2, y + 0.5 - size[1] / 2)
    return (r >= lo) & (r < hi)


def test_the_camera_moves_without_uploading_the_scene_again(tmp_path):
    """One renderer, three poses: the first pose again gives the same bytes; a pose made with
    look_at sees what `fisheye render --camera` sees from there (the same triangle at all but
    the pixels the scene's upload origin rounds across an edge)."""
    renderer = fr.Renderer(fr.Scene.load("builtin:default"))
    lens = fr.Lens.from_spec("canon-8-15mm@8mm", size=(64, 48))
    first = renderer.render(lens, spp=1, outputs=["id", "colour"])
    pose = fr.look_at((1.0, 1.2, 2.0), (-1.0, 1.0, -2.0))
    moved = renderer.render(lens, pose=pose, spp=1, outputs=["id", "colour"])
    again = renderer.render(lens, spp=1, outputs=["id", "colour"])
    assert not np.array_equal(first["id"], moved["id"])
    assert first["colour"].tobytes() == again["colour"].tobytes()
    out = tmp_path / "moved.png"
    fisheye(
        "render", "builtin:default", "--lens", "canon-8-15mm@8mm", "--size", "64x48",
        "--spp", "1", "--camera", "1,1.2,2:-1,1,-2", "--outputs", "id", "-o", str(out),
    )
    ids = np.load(tmp_path / "moved.id.npy")
    assert np.mean(ids == moved["id"]) > 0.999


def test_poses_and_sizes_take_tuples_lists_and_arrays():
    """A pose's points and a lens's size may be tuples, lists or numpy arrays (of floats or
    integers): each gives the same as the tuple."""
    pose = fr.look_at((1.0, 1.2, 2.0), (-1.0, 1.0, -2.0), (0.0, 1.0, 0.0))
    assert np.array_equal(pose, fr.look_at([1.0, 1.2, 2.0], [-1, 1, -2]))
    assert np.array_equal(pose, fr.look_at(np.array([1.0, 1.2, 2.0]), np.array([-1, 1, -2]), up=[0, 1, 0]))
    # A camera at the origin looking down -z, level with +y: OpenCV's x right, y down, z forward.
    assert np.allclose(
        fr.look_at([0, 0, 0], [0, 0, -1]),
        [[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]],
    )
    assert fr.Lens.from_spec("samyang-7.5mm", size=[64, 48]).size == (64, 48)
    assert fr.Lens.from_spec("samyang-7.5mm", size=np.array([64, 48])).size == (64, 48)


def test_the_gil_is_released_while_the_gpu_renders():
    """Another Python thread runs while a render is in flight."""
    renderer = fr.Renderer(fr.Scene.load("builtin:default"))
    # A render long enough to tell (about a second on lavapipe; larger on a fast GPU).
    for size, spp in [((320, 240), 16), ((1024, 768), 64), ((2048, 1536), 256)]:
        lens = fr.Lens.from_spec("samyang-7.5mm", size=size)
        renderer.render(lens, spp=spp, outputs=["colour"])  # make the pass once
        begun = time.perf_counter()
        renderer.render(lens, spp=spp, outputs=["colour"])
        if time.perf_counter() - begun > 0.3:
            break
    ended = []
    worker = threading.Thread(
        target=lambda: (renderer.render(lens, spp=spp, outputs=["colour"]), ended.append(time.perf_counter()))
    )
    started = time.perf_counter()
    worker.start()
    time.sleep(0.02)
    ran = time.perf_counter()
    worker.join()
    assert ended[0] - started > 0.1, "the render was too quick to tell"
    assert ran < ended[0], "the main thread waited for the render: the GIL was held"


def test_bad_input_raises_with_the_librarys_message(tmp_path):
    """Every mistake is an exception naming what is wrong; none crashes the interpreter."""
    cases = [
        (lambda: fr.Lens.from_spec("nope:f=1", size=(10, 10)), ValueError, "nope"),
        (lambda: fr.Lens.from_spec("equidistant:f=0", size=(10, 10)), ValueError, "f"),
        (lambda: fr.Lens.from_spec("equidistant:f=1", size=(0, 10)), ValueError, "0x10"),
        (lambda: fr.Lens.from_calibration(tmp_path / "none.yaml"), ValueError, "none.yaml"),
        (lambda: fr.Scene.load(tmp_path / "none.obj"), Exception, "none.obj"),
        (lambda: fr.Scene.load("builtin:nope"), ValueError, "nope"),
        (lambda: fr.Renderer(fr.Scene.load("builtin:default"), bvh="best"), ValueError, "bvh"),
        (lambda: fr.look_at((0, 0, 0), (0, 0, 0)), ValueError, "same point"),
        (lambda: fr.look_at((0, 0), (0, 0, 1)), ValueError, "eye"),
        (lambda: fr.look_at((0, 0, 0), [[0, 0, 1]]), ValueError, "target"),
        (lambda: fr.look_at((0, 0, 0), (0, 0, 1), up=(0, float("nan"), 0)), ValueError, "up"),
        (lambda: fr.Lens.from_spec("samyang-7.5mm", size=(10, 10, 3)), ValueError, "size"),
    ]
    lens = fr.Lens.from_spec("samyang-7.5mm", size=(16, 12))
    cases += [
        (lambda: lens.unproject([[1, 2, 3]]), ValueError, "(..., 2)"),
        (lambda: lens.project([1, 2]), ValueError, "(..., 3)"),
        (lambda: lens.unproject([[1, 2]], pixel_origin="centre"), ValueError, "pixel_origin"),
        (lambda: lens.unproject([["a", "b"]]), Exception, ""),
    ]
    renderer = fr.Renderer(fr.Scene.load("builtin:default"))
    shear = np.eye(4)
    shear[0, 1] = 0.5
    cases += [
        (lambda: renderer.render(lens, outputs=["disparity"]), ValueError, "disparity"),
        (lambda: renderer.render(lens, spp=3), ValueError, "3"),
        (lambda: renderer.render(lens, spp=0), ValueError, "0"),
        (lambda: renderer.render(lens, spp="auto:x"), ValueError, "threshold"),
        (lambda: renderer.render(lens, spp="most"), ValueError, "auto[:THRESHOLD[:MAX[:LEAST]]]"),
        (lambda: renderer.render(lens, pose=np.eye(3)), ValueError, "4×4"),
        (lambda: renderer.render(lens, pose=shear), ValueError, "rotation"),
        (lambda: renderer.render(lens, tone="filmic"), ValueError, "tone"),
        (lambda: renderer.render(lens, filter="gauss"), ValueError, "tent"),
        (lambda: renderer.render(lens, exposure=float("nan")), ValueError, "exposure"),
    ]
    for call, kind, text in cases:
        with pytest.raises(kind) as caught:
            call()
        assert text in str(caught.value), (text, str(caught.value))
    # Still alive, and still rendering.
    assert renderer.render(lens, spp=1, outputs=["mask"])["mask"].shape == (12, 16)


@pytest.mark.parametrize("fmt,suffix", [("opencv-yaml", "yaml"), ("opencv-xml", "xml")])
def test_opencv_calibration_files_read_back_in_cv2_filestorage(tmp_path, fmt, suffix):
    """`fisheye lens convert` writes OpenCV files that OpenCV's own reader takes, holding the
    values written (the principal point in OpenCV's convention) and the model's flag."""
    k = KB
    spec = "kb:fx={fx},fy={fy},cx={cx},cy={cy},k1={},k2={},k3={},k4={}".format(*k["k"], **k)
    out = tmp_path / f"cam.{suffix}"
    fisheye("lens", "convert", "--lens", spec, "--size", "640x480", "--format", fmt, "-o", str(out))
    fs = cv2.FileStorage(str(out), cv2.FILE_STORAGE_READ)
    assert fs.isOpened()
    K = fs.getNode("camera_matrix").mat()
    D = fs.getNode("distortion_coefficients").mat().ravel()
    assert int(fs.getNode("image_width").real()) == 640
    assert int(fs.getNode("image_height").real()) == 480
    assert int(fs.getNode("fisheye_model").real()) == 1
    assert np.array_equal(K, [[k["fx"], 0, k["cx"]], [0, k["fy"], k["cy"]], [0, 0, 1]])
    assert np.array_equal(D, k["k"])
    # And the package reads it back as the same lens.
    lens = fr.Lens.from_calibration(out)
    assert lens.size == (640, 480)
    d = directions(100, np.radians(60))
    direct = fr.Lens.from_spec(spec, size=(640, 480))
    assert np.array_equal(lens.project(d), direct.project(d), equal_nan=True)


def test_the_type_stubs_name_everything_the_module_has():
    """fisheye_rt.pyi declares every public class, method and function, and parses."""
    stub = ast.parse((ROOT / "python" / "fisheye_rt.pyi").read_text())
    declared = {}
    for node in stub.body:
        if isinstance(node, ast.ClassDef):
            declared[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        elif isinstance(node, ast.FunctionDef):
            declared[node.name] = set()
    for name in dir(fr):
        if name.startswith("_") or inspect.ismodule(getattr(fr, name)):
            continue
        assert name in declared, f"{name} is not in the stubs"
        if isinstance(getattr(fr, name), type):
            members = {m for m in dir(getattr(fr, name)) if not m.startswith("_")}
            assert members <= declared[name], (name, members - declared[name])


def python_blocks(path):
    """The ```python blocks of a Markdown file, in order."""
    text = path.read_text()
    return [block.split("```", 1)[0] for block in text.split("```python\n")[1:]]


def test_the_docs_python_examples_run_as_written():
    """Every Python block of the README and the book runs as written: the README's
    front-page example, then the Python page's, which checks its own results."""
    blocks = python_blocks(ROOT / "README.md")
    assert len(blocks) == 1
    scope = {}
    exec(compile(blocks[0], "README.md (Python)", "exec"), scope)
    assert scope["out"]["srgb"].shape == (480, 640, 4)
    assert scope["out"]["range"].dtype == np.float32
    # The Python page's example is run below, where its results are checked.
    pages = sorted(p for p in (ROOT / "docs" / "src").glob("*.md") if p.name != "python.md")
    for page in pages:
        for k, code in enumerate(python_blocks(page)):
            scope = {}
            exec(compile(code, f"{page.name} (Python block {k})", "exec"), scope)
    # The Python page's example: a pixel outside the image has no ray.
    python_page = python_blocks(ROOT / "docs" / "src" / "python.md")[0]
    scope = {}
    exec(compile(python_page, "python.md", "exec"), scope)
    assert scope["out"]["srgb"].shape == (768, 1024, 4)
    assert np.isnan(scope["dirs"][1]).all() and not np.isnan(scope["dirs"][0]).any()


@pytest.mark.parametrize("obj", ["scanned/stanford-bunny.obj", "scanned/buddha.obj"])
def test_gltf_written_by_trimesh_renders_as_its_obj(tmp_path, obj):
    """An OBJ exported to GLB by another tool (trimesh, unprocessed) renders the same surface
    through `fisheye render`: the same pixels hit, the same distances (f32 rounding: 1e-5),
    and on average the same colours (trimesh adds smooth vertex normals the OBJ lacks)."""
    import trimesh

    source = ROOT / "scenes" / obj
    glb = tmp_path / "twin.glb"
    trimesh.load(source, process=False).export(glb)
    images = {}
    for name, scene in [("obj", source), ("glb", glb)]:
        out = tmp_path / f"{name}.png"
        fisheye("render", str(scene), "--size", "96x72", "--spp", "1", "--outputs", "range",
                "-o", str(out))
        images[name] = (np.load(tmp_path / f"{name}.range.npy"),
                        np.asarray(Image.open(out)).astype(float))
    (a, x), (b, y) = images["obj"], images["glb"]
    assert np.array_equal(a > 0, b > 0)
    hit = a > 0
    assert hit.mean() > 0.02  # something is in view (the Buddha covers 4%)
    assert np.max(np.abs(a[hit] - b[hit]) / a[hit]) < 1e-5
    assert np.mean(np.abs(x - y)[..., :3]) < 2.0  # of 255


def test_flow_files_read_back_in_opencv_and_as_kitti_stores_them(tmp_path):
    """`dataset render --outputs flow --flow-format flo` writes what `cv2.readOpticalFlow`
    reads as the NPY flow (unknown flow above Middlebury's 1e9), and `--flow-format kitti` a
    16-bit PNG that `cv2.imread` reads as KITTI's devkit stores it: (u·64 + 2^15, v·64 + 2^15,
    valid) in RGB, to 1/64 px."""
    common = [
        "dataset", "render", "--trajectory", str(ROOT / "scenes/dataset/room-loop.tum"),
        "--t-scene-world", "z-up", "--lens", "equidistant:f=0.6", "--size", "48x36",
        "--spp", "1", "--outputs", "flow",
    ]
    sets = {}
    for kind in ["arrays", "flo", "kitti"]:
        sets[kind] = tmp_path / kind
        fisheye(*common, "--flow-format", kind, "-o", str(sets[kind]))
    stem = "cam0/000003_0.3"
    flow = np.load(sets["arrays"] / f"{stem}.flow.npy")
    valid = np.load(sets["arrays"] / f"{stem}.flow_valid.npy")
    known = ~np.isnan(flow[..., 0])
    assert known.sum() > 500 and valid.sum() > 0.8 * known.sum()

    flo = cv2.readOpticalFlow(str(sets["flo"] / f"{stem}.flow.flo"))
    assert flo.shape == flow.shape and flo.dtype == np.float32
    assert np.array_equal(flo[known], flow[known])
    assert np.all(flo[~known] > 1e9)

    bgr = cv2.imread(str(sets["kitti"] / f"{stem}.flow.png"), cv2.IMREAD_UNCHANGED)
    assert bgr.dtype == np.uint16 and bgr.shape == flow.shape[:2] + (3,)
    u = (bgr[..., 2].astype(np.float64) - 2**15) / 64.0
    v = (bgr[..., 1].astype(np.float64) - 2**15) / 64.0
    assert np.max(np.abs(u[known] - flow[known][:, 0])) <= 1 / 128 + 1e-9
    assert np.max(np.abs(v[known] - flow[known][:, 1])) <= 1 / 128 + 1e-9
    assert np.array_equal(bgr[..., 0], valid.astype(np.uint16) * known)
