//! The tent filter (`PixelFilter::Tent`, `wgsl/tent.wgsl`) on the device the tests run on: in
//! frames of one ray a pixel at most, every pixel becomes the 3 × 3 weighted mean this file
//! computes for itself from the box-filtered frame (weights 1/8, 3/4, 1/8 along each axis,
//! the lens's masked neighbours left out); masked pixels, the geometry and the ids are the
//! box-filtered frame's bit for bit; frames of more rays are unchanged; and the error against
//! a many-ray reference falls.

mod common;

use common::{camera, ctx, scene};
use fisheye_rt::compare::image_error;
use fisheye_rt::lens::LensCamera;
use fisheye_rt::scene::Scene;
use fisheye_rt::trace::{
    Adaptive, FramePass, GpuScene, PixelFilter, RenderOptions, RenderOutput, TracePass, render,
};

/// A frame of `scene` through `cam` as `options` say, and (adaptive sampling) the rays each
/// pixel's colour took.
fn frame(scene: &Scene, cam: &LensCamera, options: &RenderOptions) -> (RenderOutput, Vec<u32>) {
    let gpu = GpuScene::new(ctx(), scene, options).unwrap();
    let pass = FramePass::new(ctx(), cam, &gpu, options).unwrap();
    let out = pass.trace(ctx(), &gpu, &scene.camera, "tent test").unwrap();
    let rays = match &pass {
        FramePass::Adaptive(adaptive) => adaptive.read_rays(ctx()).unwrap(),
        FramePass::Uniform(_) => vec![options.spp; out.colour.len()],
    };
    (out, rays)
}

fn sampled(spp: u32, threshold: Option<f32>, filter: PixelFilter) -> RenderOptions {
    RenderOptions {
        spp,
        adaptive: threshold.map(|threshold| Adaptive {
            threshold,
            ground_truth: true,
            every_pixel: false,
        }),
        filter,
        ..RenderOptions::default()
    }
}

/// The tent filter of pixel (x, y) of `colour`, in f64: this test's own statement of it.
fn tent_at(colour: &[[f32; 4]], width: usize, x: usize, y: usize) -> [f64; 3] {
    let side = [0.125, 0.75, 0.125];
    let height = colour.len() / width;
    let (mut sum, mut weights) = ([0.0f64; 3], 0.0);
    for (dy, wy) in side.iter().enumerate() {
        for (dx, wx) in side.iter().enumerate() {
            let (Some(nx), Some(ny)) = ((x + dx).checked_sub(1), (y + dy).checked_sub(1)) else {
                continue;
            };
            if nx >= width || ny >= height || colour[ny * width + nx][3] == 0.0 {
                continue;
            }
            let c = colour[ny * width + nx];
            for k in 0..3 {
                sum[k] += wx * wy * f64::from(c[k]);
            }
            weights += wx * wy;
        }
    }
    sum.map(|s| s / weights)
}

/// Holds `tent` to the filter of `boxed` (the same frame with the box filter): every pixel the
/// lens covers filtered, within f32 rounding of a sum of nine terms; masked pixels, the
/// geometry and the ids unchanged. Returns how many pixels were filtered.
fn check_filtered(boxed: &RenderOutput, tent: &RenderOutput) -> usize {
    assert_eq!(tent.geometry, boxed.geometry, "geometry");
    assert_eq!(tent.ids, boxed.ids, "ids");
    let width = boxed.size.width as usize;
    let mut filtered = 0;
    for (i, (b, t)) in boxed.colour.iter().zip(&tent.colour).enumerate() {
        if b[3] == 0.0 {
            assert_eq!(t, b, "masked pixel {i}");
            continue;
        }
        filtered += 1;
        let wanted = tent_at(&boxed.colour, width, i % width, i / width);
        for k in 0..3 {
            let tolerance = 1e-6 * wanted[k].abs().max(1.0);
            let got = f64::from(t[k]);
            assert!(
                (got - wanted[k]).abs() <= tolerance,
                "pixel {i} channel {k}: {got} against {}",
                wanted[k]
            );
        }
        assert_eq!(t[3], b[3], "pixel {i}: alpha is the pixel's own coverage");
    }
    filtered
}

/// Uniform sampling at one ray: every pixel the lens covers is filtered, those at the image
/// circle's rim from their covered neighbours alone (a 180° lens, so the rim is in the
/// frame); at four rays the filter changes nothing.
#[test]
fn one_ray_pixels_take_the_tent_filter_of_their_neighbours() {
    let room = scene("builtin:default");
    let cam = camera("canon-8-15mm@8mm", 61, 46);
    let (boxed, _) = frame(&room, &cam, &sampled(1, None, PixelFilter::Box));
    let (tent, _) = frame(&room, &cam, &sampled(1, None, PixelFilter::Tent));
    let covered = boxed.counts().0;
    assert!(covered < 61 * 46, "the lens masks the corners");
    assert_eq!(check_filtered(&boxed, &tent), covered);
    assert_ne!(tent.colour, boxed.colour, "the filter changed the image");
    let (four, _) = frame(&room, &cam, &sampled(4, None, PixelFilter::Box));
    let (four_tent, _) = frame(&room, &cam, &sampled(4, None, PixelFilter::Tent));
    assert_eq!(
        four_tent.colour, four.colour,
        "several rays a pixel keep their mean"
    );
}

/// Adaptive sampling at one ray at most (`auto:T:1`): its interpolated and its one-ray
/// pixels alike are filtered, the ground truth untouched; with supersampling (`auto:T`, 16 at
/// most) the filter changes nothing.
#[test]
fn adaptive_sampling_at_one_ray_is_filtered_whole() {
    let room = scene("builtin:default");
    let cam = camera("canon-8-15mm@8mm", 128, 96);
    let (boxed, rays) = frame(&room, &cam, &sampled(1, Some(0.1), PixelFilter::Box));
    let (tent, tent_rays) = frame(&room, &cam, &sampled(1, Some(0.1), PixelFilter::Tent));
    assert_eq!(tent_rays, rays, "the filter changes no ray");
    let covered = |i: usize| boxed.colour[i][3] > 0.0;
    let kinds = [0, 1].map(|n| {
        (0..rays.len())
            .filter(|&i| covered(i) && rays[i] == n)
            .count()
    });
    assert!(
        kinds.iter().all(|&n| n > 0),
        "interpolated and one-ray pixels: {kinds:?}"
    );
    assert_eq!(check_filtered(&boxed, &tent), kinds[0] + kinds[1]);
    let (sixteen, _) = frame(&room, &cam, &sampled(16, Some(0.1), PixelFilter::Box));
    let (sixteen_tent, _) = frame(&room, &cam, &sampled(16, Some(0.1), PixelFilter::Tent));
    assert_eq!(
        sixteen_tent.colour, sixteen.colour,
        "supersampled frames are unchanged"
    );
}

/// What the filter is for: one centre sample aliases at edges, and the filtered frame is
/// nearer the many-ray reference's box averages. Textures are left off: a ray's lookup is
/// filtered at its pixel's footprint already, and the tent blurs them a second time (on the
/// textured room here the MSE rises, 1.22e-3 to 1.34e-3). Measured on the shared scenes at
/// 256×192 before textures were filtered (the book's "Adaptive sampling") the MSE fell 2.1 to
/// 3.2 times, and here 2.1 to 2.5 times (two built-in scenes at 96×72, lavapipe): it must fall by 40 % at
/// least.
#[test]
fn the_tent_filter_brings_one_ray_nearer_the_reference() {
    for name in ["builtin:default", "builtin:many-small"] {
        let mut room = scene(name);
        for m in &mut room.materials {
            m.diffuse_texture = None;
        }
        let cam = camera("samyang-7.5mm", 96, 72);
        let reference = render(ctx(), &room, &cam, &sampled(64, None, PixelFilter::Box)).unwrap();
        for threshold in [None, Some(0.1)] {
            // One ray a pixel at most: uniformly, or as `--spp auto:0.1:1`.
            let mse = |filter| {
                let (out, _) = frame(&room, &cam, &sampled(1, threshold, filter));
                image_error(&reference.colour, &out.colour).mse
            };
            let (boxed, tent) = (mse(PixelFilter::Box), mse(PixelFilter::Tent));
            assert!(
                tent < 0.6 * boxed,
                "{name}, threshold {threshold:?}: MSE {tent:.3e} with the tent, {boxed:.3e} without"
            );
        }
    }
}

/// The filter reads the whole image in one binding: an image traced in bands (its outputs
/// beyond one storage binding) is refused with the way out, not filtered in part.
#[test]
fn the_tent_filter_refuses_an_image_traced_in_bands() {
    let gpu = GpuScene::new(ctx(), &scene("builtin:default"), &RenderOptions::default()).unwrap();
    let limit = ctx().device.limits().max_storage_buffer_binding_size;
    let rows = (limit / (16 * 4096)) as u32 + 1;
    let cam = camera("equidistant:f=0.6", 4096, rows);
    let source = RenderOptions::default().directions;
    let mut pass = TracePass::supersampled(ctx(), &cam, &gpu, source, 1).unwrap();
    assert!(pass.bands() > 1);
    let message = pass
        .set_filter(ctx(), PixelFilter::Tent)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("one storage binding") && message.contains("--filter box"),
        "{message}"
    );
    // At 4 rays a pixel the tent changes nothing, so nothing is refused.
    let mut four = TracePass::supersampled(ctx(), &cam, &gpu, source, 4).unwrap();
    four.set_filter(ctx(), PixelFilter::Tent).unwrap();
    assert_eq!(four.filter(), PixelFilter::Box);
}
