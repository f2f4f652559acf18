#!/usr/bin/env python3
"""Warps each frame of a dataset onto the one before it with its optical flow (numpy, Pillow).

    python3 examples/warp_with_flow.py DATASET_FOLDER [CAMERA]

The dataset needs `--outputs flow` (`fisheye dataset render`). For frame k, `flow` says where
each pixel's hit lands in frame k+1 and `flow_valid` whether frame k+1 sees it there. Sampling
frame k+1's colour at pixel + flow (bilinearly) therefore rebuilds frame k wherever flow_valid
is 1: the example prints, over those pixels, the mean colour difference between frame k and
the warped frame k+1, beside the difference without warping, and writes the first pair's
warped image (invalid pixels black) as warped.png in the dataset's folder. It exits 1 if
warping does not bring the frames closer, so it checks the flow as it shows how to use it.
"""
import json
import os
import sys

import numpy as np
from PIL import Image


def bilinear(image, x, y):
    """`image` (H, W, C) sampled at continuous positions (pixel centres at i + 0.5)."""
    h, w = image.shape[:2]
    x, y = np.clip(x - 0.5, 0, w - 1), np.clip(y - 0.5, 0, h - 1)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    top = image[y0, x0] * (1 - fx) + image[y0, x1] * fx
    bottom = image[y1, x0] * (1 - fx) + image[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def main(folder, camera="cam0"):
    with open(os.path.join(folder, "manifest.json")) as f:
        manifest = json.load(f)
    views = [v for frame in manifest["frames"] for v in frame["views"] if v["camera"] == camera]
    pairs = [(a["files"], b["files"]) for a, b in zip(views, views[1:])
             if "flow" in a["files"] and b["files"]]
    if not pairs:
        raise SystemExit(f"{folder}: no frame of {camera} has flow and a next frame "
                         "(render with --outputs flow)")
    warped_error, still_error, pixels = 0.0, 0.0, 0
    for k, (this, after) in enumerate(pairs):
        flow = np.load(os.path.join(folder, this["flow"]))
        valid = np.load(os.path.join(folder, this["flow_valid"])).astype(bool)
        first = np.asarray(Image.open(os.path.join(folder, this["colour"])), np.float64)[..., :3]
        second = np.asarray(Image.open(os.path.join(folder, after["colour"])), np.float64)[..., :3]
        h, w = valid.shape
        ys, xs = np.mgrid[0:h, 0:w] + 0.5
        warped = bilinear(second, xs + np.nan_to_num(flow[..., 0]), ys + np.nan_to_num(flow[..., 1]))
        warped_error += np.abs(warped - first)[valid].mean(axis=1).sum()
        still_error += np.abs(second - first)[valid].mean(axis=1).sum()
        pixels += valid.sum()
        if k == 0:
            shown = np.where(valid[..., None], warped, 0).round().astype(np.uint8)
            Image.fromarray(shown).save(os.path.join(folder, "warped.png"))
    warped_error, still_error = warped_error / pixels, still_error / pixels
    print(f"{camera}: {len(pairs)} pairs, {pixels} covisible pixels: frame k+1 warped onto frame "
          f"k by the flow differs by {warped_error:.2f} of 255 on average, "
          f"{still_error:.2f} without warping; wrote {os.path.join(folder, 'warped.png')}")
    if not warped_error < still_error:
        sys.exit(1)


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        raise SystemExit(__doc__)
    main(*sys.argv[1:])
