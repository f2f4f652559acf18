#!/usr/bin/env python3
"""Loads a dataset written by `fisheye dataset render` (numpy and Pillow).

    python3 examples/load_dataset.py DATASET_FOLDER

For every frame and camera it loads the colour image and the ground-truth arrays the manifest
lists. Where a frame has `range` and `direction`, it also checks the dataset against itself
the way a user's own pipeline would: each pixel's hit point (range x direction, in the scene)
is moved into the camera with the manifest's T_scene_camera and projected with the camera's
OpenCV calibration (cv::fisheye's Kannala-Brandt or the pinhole model), which must land on the
pixel's centre. Where it has `point` (the hit in the camera's frame), that is projected
likewise, and its z must be the `depth` and its length the `range` where those are there too.
It prints the largest distances in pixels.
"""
import json
import os
import sys

import numpy as np
from PIL import Image


def load(folder):
    with open(os.path.join(folder, "manifest.json")) as f:
        manifest = json.load(f)
    if manifest.get("layout") != "fisheye-rt dataset 1":
        raise SystemExit(f"{folder}: not a fisheye-rt dataset (layout {manifest.get('layout')!r})")
    return manifest


def frames(folder, manifest):
    """Yields (frame, camera, arrays): the colour image as an (H, W, 4) array and every ground
    truth array, by name."""
    cameras = {c["name"]: c for c in manifest["cameras"]}
    for frame in manifest["frames"]:
        for view in frame["views"]:
            arrays = {}
            for what, name in view["files"].items():
                path = os.path.join(folder, name)
                if name.endswith(".npy"):
                    arrays[what] = np.load(path)
                elif name.endswith(".png"):
                    arrays[what] = np.asarray(Image.open(path))
                else:
                    arrays[what] = path  # EXR: read it with OpenEXR or imageio
            yield frame, view, cameras[view["camera"]], arrays


def project(camera, points):
    """Pixels (OpenCV's convention: the top-left pixel's centre at (0, 0)) of camera-frame
    points, with the camera's OpenCV model."""
    cv = camera["opencv"]
    k = np.array(cv["camera_matrix"])
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    if cv["model"] == "cv::fisheye":
        k1, k2, k3, k4 = cv["distortion_coefficients"]
        r = np.hypot(x, y)
        theta = np.arctan2(r, z)
        t2 = theta * theta
        theta_d = theta * (1 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))))
        scale = np.where(r > 0, theta_d / np.maximum(r, 1e-300), 1.0 / z)
        u, v = x * scale, y * scale
    elif cv["model"] == "cv::calibrateCamera":
        k1, k2, p1, p2, k3 = cv["distortion_coefficients"]
        a, b = x / z, y / z
        r2 = a * a + b * b
        radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
        u = a * radial + 2 * p1 * a * b + p2 * (r2 + 2 * a * a)
        v = b * radial + p1 * (r2 + 2 * b * b) + 2 * p2 * a * b
    else:
        return None  # no OpenCV model: use the project's own (fisheye lens project)
    return np.stack([k[0, 0] * u + k[0, 2], k[1, 1] * v + k[1, 2]], axis=1)


def reprojection_error(camera, view, arrays):
    """Largest distance in pixels between each hit pixel's centre and where its hit point
    projects, or None without range and direction."""
    if "range" not in arrays or "direction" not in arrays:
        return None
    rng, direction = arrays["range"], arrays["direction"]
    hit = rng > 0
    t = np.array(view["T_scene_camera"])
    points = t[:3, 3] + direction[hit] * rng[hit][:, None]  # hit points in the scene
    camera_points = (points - t[:3, 3]) @ t[:3, :3]  # R^T (p - t), row by row
    return pixel_error(camera, hit, camera_points)


def pixel_error(camera, hit, camera_points):
    """Largest distance in pixels between the centres of the pixels where `hit` is true (in
    row order) and where their camera-frame points project, or None without an OpenCV model."""
    pixels = project(camera, camera_points)
    if pixels is None:
        return None
    rows, cols = np.nonzero(hit)
    centres = np.stack([cols, rows], axis=1).astype(np.float64)
    return float(np.max(np.linalg.norm(pixels - centres, axis=1), initial=0.0))


def point_error(camera, arrays):
    """Largest distance in pixels between each hit pixel's centre and where its camera-frame
    point projects, or None without points; checks the point against the depth and range."""
    if "point" not in arrays:
        return None
    point = arrays["point"]
    hit = np.any(point != 0, axis=2)
    if "depth" in arrays:
        assert np.array_equal(arrays["depth"], point[..., 2]), "depth is not the point's z"
    if "range" in arrays:
        length = np.linalg.norm(point.astype(np.float64), axis=2)
        assert np.array_equal(hit, arrays["range"] > 0), "points where no range, or none where one"
        assert np.allclose(length, arrays["range"], rtol=1e-6, atol=0), "|point| is not the range"
    return pixel_error(camera, hit, point[hit].astype(np.float64))


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    folder = sys.argv[1]
    manifest = load(folder)
    images = 0
    worst = {"hit points": None, "camera-frame points": None}
    for frame, view, camera, arrays in frames(folder, manifest):
        colour = arrays["colour"]
        if not isinstance(colour, str):
            assert colour.shape[:2] == (camera["height"], camera["width"]), colour.shape
        images += 1
        for what, error in [
            ("hit points", reprojection_error(camera, view, arrays)),
            ("camera-frame points", point_error(camera, arrays)),
        ]:
            if error is not None:
                worst[what] = error if worst[what] is None else max(worst[what], error)
    print(f"{len(manifest['frames'])} frames, {len(manifest['cameras'])} cameras, {images} images")
    for what, error in worst.items():
        if error is not None:
            print(f"{what} reproject to their pixels within {error:.2e} px")


if __name__ == "__main__":
    main()
