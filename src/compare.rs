//! How wrong each method is: error against a reference image over the pixels both have
//! ([`ImageError`]), an image of where the error is ([`error_map`]), the supersampled
//! reference for anti-aliased comparisons ([`supersampled`]), and which setups no other beats
//! in both time and error ([`pareto_front`]).
//!
//! Errors are measured on what a viewer sees: colours clamped to [0, 1] and sRGB-encoded, as
//! the PNGs hold them, so an MSE of 0.001 (the thesis's "0.1 %") is a mean squared difference
//! of 0.1 % of full scale, and PSNR is `10 log10(1 / MSE)` dB.

use serde::Serialize;

use crate::error::Result;
use crate::gpu::GpuContext;
use crate::lens::gpu::DirectionSource;
use crate::lens::{ImageSize, LensCamera};
use crate::scene::Camera;
use crate::trace::{GpuScene, TracePass, linear_to_srgb};

/// A lens image's error against a reference of the same size.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImageError {
    /// Mean squared difference per channel over the pixels valid in both (sRGB, [0, 1]).
    pub mse: f64,
    /// Peak signal-to-noise ratio in dB, `10 log10(1 / mse)`; infinite (JSON `null`) for
    /// identical images.
    pub psnr_db: f64,
    /// The largest difference of any channel of any compared pixel.
    pub max_abs: f64,
    /// The fraction of all pixels whose validity (the lens mask) agrees with the reference.
    pub mask_agreement: f64,
    /// The number of pixels compared (valid in both).
    pub compared: usize,
}

/// A linear colour channel as it is displayed: clamped, sRGB-encoded.
fn shown(c: f32) -> f64 {
    f64::from(linear_to_srgb(c.clamp(0.0, 1.0)))
}

fn valid(c: &[f32; 4]) -> bool {
    c[3] == 1.0
}

/// The error of `image` against `reference` (linear colours with the mask in `w`, as
/// [`RenderOutput::colour`](crate::trace::RenderOutput::colour)).
pub fn image_error(reference: &[[f32; 4]], image: &[[f32; 4]]) -> ImageError {
    assert_eq!(reference.len(), image.len(), "images of one size");
    let (mut sum, mut max, mut compared, mut agree) = (0.0, 0.0f64, 0, 0);
    for (r, m) in reference.iter().zip(image) {
        agree += usize::from(valid(r) == valid(m));
        if valid(r) && valid(m) {
            compared += 1;
            for c in 0..3 {
                let d = shown(r[c]) - shown(m[c]);
                sum += d * d;
                max = max.max(d.abs());
            }
        }
    }
    let mse = sum / (3 * compared.max(1)) as f64;
    ImageError {
        mse,
        psnr_db: -10.0 * mse.log10(),
        max_abs: max,
        mask_agreement: agree as f64 / reference.len().max(1) as f64,
        compared,
    }
}

/// Differences at or above this (of full scale, sRGB) are drawn white in [`error_map`].
pub const ERROR_MAP_FULL_SCALE: f64 = 0.25;

/// An image of the error of `image` against `reference`: per pixel the largest channel
/// difference on a black-red-yellow-white ramp (square-root scale, white at
/// [`ERROR_MAP_FULL_SCALE`]), magenta where only one of the two has a ray, transparent where
/// neither has.
pub fn error_map(size: ImageSize, reference: &[[f32; 4]], image: &[[f32; 4]]) -> image::RgbaImage {
    let mut out = image::RgbaImage::new(size.width, size.height);
    for ((r, m), pixel) in reference.iter().zip(image).zip(out.pixels_mut()) {
        *pixel = match (valid(r), valid(m)) {
            (false, false) => image::Rgba([0, 0, 0, 0]),
            (true, true) => {
                let e = (0..3)
                    .map(|c| (shown(r[c]) - shown(m[c])).abs())
                    .fold(0.0, f64::max);
                let t = (e / ERROR_MAP_FULL_SCALE).min(1.0).sqrt() * 3.0;
                let ramp = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
                image::Rgba([ramp(t), ramp(t - 1.0), ramp(t - 2.0), 255])
            }
            _ => image::Rgba([255, 0, 255, 255]),
        };
    }
    out
}

/// The largest supersampling factor (at most 4) whose `factor² × pixels` image fits the
/// device's storage-binding limit, at least 1.
pub fn supersample_factor(ctx: &GpuContext, size: ImageSize) -> u32 {
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    (1..=4u32)
        .rev()
        .find(|f| 16 * u64::from(f * f) * size.pixels() as u64 <= limit)
        .unwrap_or(1)
}

/// The supersampled reference: direct ray tracing of `factor × factor` stratified rays per
/// pixel (a `factor` times larger image through the same lens, which covers the same field),
/// averaged per pixel (a box filter over the valid rays, in linear radiance). The mask is
/// `centres`' (the reference at pixel centres), so both references compare the same pixels.
pub fn supersampled(
    ctx: &GpuContext,
    scene: &GpuScene,
    camera: &LensCamera,
    pose: &Camera,
    factor: u32,
    centres: &[[f32; 4]],
) -> Result<Vec<[f32; 4]>> {
    let size = camera.size;
    let large = camera.scaled(factor)?;
    let pass = TracePass::new(ctx, &large, scene, DirectionSource::Computed)?;
    pass.set_pose(ctx, scene, pose);
    let fine = pass
        .trace(ctx, scene, "tracing the supersampled reference")?
        .colour;
    let (w, f) = (size.width as usize, factor as usize);
    Ok(centres
        .iter()
        .enumerate()
        .map(|(p, &centre)| {
            if !valid(&centre) {
                return [0.0; 4];
            }
            let (i, j) = (p % w, p / w);
            let mut sum = [0.0f64; 3];
            let mut n = 0;
            for b in 0..f {
                let row = (j * f + b) * w * f;
                for c in &fine[row + i * f..row + i * f + f] {
                    if valid(c) {
                        n += 1;
                        for k in 0..3 {
                            sum[k] += f64::from(c[k]);
                        }
                    }
                }
            }
            if n == 0 {
                // Every sub-ray masked: only possible on the rim of an even factor.
                return centre;
            }
            let mean = |k: usize| (sum[k] / f64::from(n)) as f32;
            [mean(0), mean(1), mean(2), 1.0]
        })
        .collect())
}

/// For points `(time, error)`, whether each is on the Pareto front: no other point is at
/// least as good in both and better in one.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    points
        .iter()
        .map(|&(t, e)| {
            !points
                .iter()
                .any(|&(t2, e2)| t2 <= t && e2 <= e && (t2 < t || e2 < e))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_follow_their_definitions() {
        let grey = |v: f32| [v, v, v, 1.0];
        let none = [0.0; 4];
        // sRGB(0.5) ≈ 0.7354, sRGB(1) = 1: one pixel differs, one matches, one mask differs.
        let reference = [grey(1.0), grey(0.5), grey(0.2), none];
        let image = [grey(0.5), grey(0.5), none, none];
        let e = image_error(&reference, &image);
        let d = shown(1.0) - shown(0.5);
        assert!((d - (1.0 - 0.7354)).abs() < 1e-4);
        assert_eq!(e.compared, 2);
        assert!((e.mse - d * d / 2.0).abs() < 1e-12);
        assert!((e.psnr_db - -10.0 * (d * d / 2.0).log10()).abs() < 1e-9);
        assert!((e.max_abs - d).abs() < 1e-12);
        assert_eq!(e.mask_agreement, 0.75);
        // Over-bright values are clamped as displayed: no error between 1 and 3.
        let bright = image_error(&[grey(1.0)], &[grey(3.0)]);
        assert_eq!(bright.mse, 0.0);
        assert!(bright.psnr_db.is_infinite());
    }

    #[test]
    fn the_error_map_marks_masks_and_scales_errors() {
        let size = ImageSize::new(4, 1).unwrap();
        let reference = [
            [0.0, 0.0, 0.0, 1.0],
            [1.0; 4],
            [0.0; 4],
            [0.5, 0.5, 0.5, 1.0],
        ];
        let image = [
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 0.0, 0.0, 1.0],
            [0.0; 4],
            [0.0; 4],
        ];
        let map = error_map(size, &reference, &image);
        assert_eq!(map.get_pixel(0, 0).0, [0, 0, 0, 255]); // no error
        assert_eq!(map.get_pixel(1, 0).0, [255, 255, 255, 255]); // full scale
        assert_eq!(map.get_pixel(2, 0).0, [0, 0, 0, 0]); // neither has a ray
        assert_eq!(map.get_pixel(3, 0).0, [255, 0, 255, 255]); // the masks disagree
    }

    #[test]
    fn the_pareto_front_keeps_undominated_points() {
        let points = [
            (1.0, 5.0),
            (2.0, 3.0),
            (3.0, 3.0),
            (4.0, 1.0),
            (5.0, 2.0),
            (1.0, 5.0),
        ];
        assert_eq!(
            pareto_front(&points),
            [true, true, false, true, false, true]
        );
    }
}
