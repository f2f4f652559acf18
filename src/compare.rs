//! How wrong each method is: error against a reference image over the pixels both have
//! ([`ImageError`]), an image of where the error is ([`error_map`]), the supersampled
//! reference of lens validation ([`supersampled`]), the perceptual ꟻLIP error
//! ([`flip_error`]), which setups no other beats in both time and error ([`pareto_front`]),
//! and the time a family of setups needs to reach an error ([`Envelope`]).
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

/// Whether the lens covers (some of) the pixel: one ray per pixel gives 0 or 1, several the
/// covered share.
fn valid(c: &[f32; 4]) -> bool {
    c[3] > 0.0
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

/// Errors within this fraction of each other are equal for the Pareto front: the reference
/// is itself an estimate, and 256 stratified rays per pixel leave it an error of up to 1/16
/// of a 16-ray setup's (independent samples; stratification does better), about 6% of the
/// compared error.
pub const EQUAL_ERROR: f64 = 0.05;

/// For points `(time, error)`, whether each is on the Pareto front: no other point is at
/// least as fast and at least as good, errors within [`EQUAL_ERROR`] counting as equal (a
/// slower point whose error is lower by noise alone is not a new point).
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    points
        .iter()
        .map(|&(t, e)| {
            !points
                .iter()
                .any(|&(t2, e2)| t2 <= t && e2 <= e * (1.0 + EQUAL_ERROR) && (t2 < t || e2 < e))
        })
        .collect()
}

/// The lower envelope of a family of setups (direct RT over rays per pixel, cube maps over
/// face sizes): the time it needs to reach an error, interpolated between its Pareto points
/// linearly in log time against log error (time and error follow power laws in rays per
/// pixel and in face size, which are straight lines there).
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    /// `(time, error)` of the family's Pareto points, fastest first (errors falling).
    pub points: Vec<(f64, f64)>,
}

impl Envelope {
    /// The envelope of `(time, error)` points: those on their [`pareto_front`] (so a slower
    /// setup within [`EQUAL_ERROR`] of a faster one is no level of its own).
    pub fn of(points: &[(f64, f64)]) -> Envelope {
        let mut front: Vec<(f64, f64)> = points
            .iter()
            .zip(pareto_front(points))
            .filter_map(|(&p, on)| on.then_some(p))
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        front.dedup();
        Envelope { points: front }
    }

    /// The least error the family reaches, and the time it takes.
    pub fn best(&self) -> Option<(f64, f64)> {
        self.points.last().copied()
    }

    /// The time the family needs to reach `error` or less: its fastest setup's where that
    /// one is good enough, interpolated between the two setups that bracket it, `None`
    /// below the family's least error.
    pub fn time_to_reach(&self, error: f64) -> Option<f64> {
        let k = self.points.iter().position(|&(_, e)| e <= error)?;
        if k == 0 {
            return Some(self.points[0].0);
        }
        let ((t0, e0), (t1, e1)) = (self.points[k - 1], self.points[k]);
        let s = (error.ln() - e0.ln()) / (e1.ln() - e0.ln());
        Some((t0.ln() + s * (t1.ln() - t0.ln())).exp())
    }
}

/// The mean ꟻLIP error (Andersson et al., "FLIP: A Difference Evaluator for Alternating
/// Images", HPG 2020; NVIDIA's implementation, through the `nv-flip` crate) of `image`
/// against `reference` over the pixels valid in both, on displayed values as [`image_error`]
/// takes them (8-bit sRGB: LDR-ꟻLIP), at 67 pixels per degree (a 0.7 m wide 4K monitor seen
/// from 0.7 m, ꟻLIP's default). 0 is identical; 1 the largest difference. Pixels valid in
/// only one image are black in both, so the mask's edge is not counted as an error.
pub fn flip_error(size: ImageSize, reference: &[[f32; 4]], image: &[[f32; 4]]) -> f64 {
    assert_eq!(reference.len(), image.len(), "images of one size");
    let both: Vec<bool> = reference
        .iter()
        .zip(image)
        .map(|(r, m)| valid(r) && valid(m))
        .collect();
    let bytes = |colour: &[[f32; 4]]| -> Vec<u8> {
        colour
            .iter()
            .zip(&both)
            .flat_map(|(c, &on)| {
                [0, 1, 2].map(|k| {
                    if on {
                        (shown(c[k]) * 255.0).round() as u8
                    } else {
                        0
                    }
                })
            })
            .collect()
    };
    let flip_image =
        |colour: Vec<u8>| nv_flip::FlipImageRgb8::with_data(size.width, size.height, &colour);
    let map = nv_flip::flip(
        flip_image(bytes(reference)),
        flip_image(bytes(image)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
    .to_vec();
    let (sum, n) = map
        .iter()
        .zip(&both)
        .filter(|&(_, &on)| on)
        .fold((0.0, 0usize), |(s, n), (&e, _)| (s + f64::from(e), n + 1));
    sum / n.max(1) as f64
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
        // Slower by a quarter for 3% less error: noise, not a new point; for 10% less, one.
        assert_eq!(pareto_front(&[(2.0, 3.0), (2.5, 2.91)]), [true, false]);
        assert_eq!(pareto_front(&[(2.0, 3.0), (2.5, 2.7)]), [true, true]);
    }

    /// Time to reach an error: the fastest setup's above its error, log-log interpolation
    /// between setups, nothing below the best.
    #[test]
    fn envelopes_interpolate_in_log_time_and_log_error() {
        // 1, 4 and 16 rays: error falls 4x per 4x time; a dominated point is left out, and so
        // is one only 2% better than a faster one.
        let family = Envelope::of(&[
            (10.0, 4e-3),
            (40.0, 1e-3),
            (50.0, 2e-3),
            (45.0, 0.98e-3),
            (160.0, 2.5e-4),
        ]);
        assert_eq!(family.points, [(10.0, 4e-3), (40.0, 1e-3), (160.0, 2.5e-4)]);
        assert_eq!(family.best(), Some((160.0, 2.5e-4)));
        assert_eq!(family.time_to_reach(1e-2), Some(10.0));
        assert_eq!(family.time_to_reach(4e-3), Some(10.0));
        let at = |e: f64| family.time_to_reach(e).unwrap();
        assert!((at(2e-3) - 20.0).abs() < 1e-9, "{}", at(2e-3));
        assert!((at(1e-3) - 40.0).abs() < 1e-9);
        assert!((at(5e-4) - 80.0).abs() < 1e-9);
        assert_eq!(family.time_to_reach(2e-4), None);
        assert_eq!(Envelope::of(&[]).time_to_reach(1.0), None);
    }

    /// ꟻLIP is NVIDIA's own implementation; these check how it is called: identical images
    /// score 0, the score grows with the difference, stays in [0, 1], and pixels outside
    /// either mask do not count.
    #[test]
    fn flip_grows_with_the_difference_and_ignores_masked_pixels() {
        let size = ImageSize::new(32, 32).unwrap();
        let pattern: Vec<[f32; 4]> = (0..1024)
            .map(|p| {
                let v = if (p % 32 / 4 + p / 128) % 2 == 0 {
                    0.8
                } else {
                    0.1
                };
                [v, v * 0.5, 0.2, 1.0]
            })
            .collect();
        assert_eq!(flip_error(size, &pattern, &pattern), 0.0);
        let shifted = |by: f32| -> Vec<[f32; 4]> {
            pattern
                .iter()
                .map(|c| [c[0] + by, c[1] + by, c[2], 1.0])
                .collect()
        };
        let (small, large) = (
            flip_error(size, &pattern, &shifted(0.02)),
            flip_error(size, &pattern, &shifted(0.2)),
        );
        assert!(
            0.0 < small && small < large && large <= 1.0,
            "{small} {large}"
        );
        let black = vec![[0.0, 0.0, 0.0, 1.0]; 1024];
        let white = vec![[1.0, 1.0, 1.0, 1.0]; 1024];
        assert!(flip_error(size, &black, &white) > 0.9);
        // Masking the whole left half of one image: only the right half is compared.
        let mut masked = shifted(0.2);
        for (p, pixel) in masked.iter_mut().enumerate() {
            if p % 32 < 16 {
                *pixel = [9.0, 0.0, 9.0, 0.0];
            }
        }
        let half = flip_error(size, &pattern, &masked);
        assert!((half - large).abs() < 0.2 * large, "{half} {large}");
    }

    /// `compare` measures a group of setups' images on every thread at once: NVIDIA's ꟻLIP
    /// (C++ behind the crate) gives each image the score it gives it alone, however many
    /// run side by side.
    #[test]
    fn flip_scores_alike_on_many_threads_at_once() {
        let size = ImageSize::new(48, 40).unwrap();
        let image = |seed: u32| -> Vec<[f32; 4]> {
            (0..48 * 40u32)
                .map(|p| {
                    let v = ((p * 7 + seed * 13) % 29) as f32 / 29.0;
                    [v, (v + 0.3 * seed as f32) % 1.0, 0.5 * v, 1.0]
                })
                .collect()
        };
        let reference = image(0);
        let mut scores: Vec<(Vec<[f32; 4]>, f64)> = (1..=16).map(|k| (image(k), -1.0)).collect();
        let alone: Vec<f64> = scores
            .iter()
            .map(|(image, _)| flip_error(size, &reference, image))
            .collect();
        std::thread::scope(|scope| {
            for (image, score) in &mut scores {
                let reference = &reference;
                scope.spawn(move || *score = flip_error(size, reference, image));
            }
        });
        let together: Vec<f64> = scores.iter().map(|(_, score)| *score).collect();
        assert_eq!(together, alone);
        assert!(alone.iter().all(|&f| f > 0.0), "{alone:?}");
    }
}
