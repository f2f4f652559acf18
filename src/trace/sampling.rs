//! Where a pixel's samples go, as `wgsl/sampling.wgsl` places them (its twin; the f64
//! reference renders the same samples, and a test holds the GPU to it): an s × s grid of
//! strata with one jittered sample in each, the jitter hashed from the pixel and the sample
//! (jittered stratified sampling: Mitchell 1987; Pharr, Jakob and Humphreys, "Physically Based
//! Rendering", 4th ed., section 8.5), so every render is the same.

use glam::DVec2;

use crate::error::{Error, Result};
use crate::shared::MAX_SAMPLES_PER_SIDE;

/// The pcg2d hash of Jarzynski and Olano ("Hash Functions for GPU Rendering", JCGT 9(3),
/// 2020): an LCG step on each lane, mixed across lanes, twice.
fn pcg2d(seed: [u32; 2]) -> [u32; 2] {
    let lcg = |x: u32| x.wrapping_mul(1664525).wrapping_add(1013904223);
    let [mut x, mut y] = seed.map(lcg);
    for _ in 0..2 {
        x = x.wrapping_add(y.wrapping_mul(1664525));
        y = y.wrapping_add(x.wrapping_mul(1664525));
        x ^= x >> 16;
        y ^= y >> 16;
    }
    [x, y]
}

/// Sample `k` of the `side` × `side` samples of pixel `index` (row-major): its offset from the
/// pixel's top-left corner, in [0, 1)². With one sample, the centre.
pub fn sample_offset(index: u32, k: u32, side: u32) -> DVec2 {
    if side == 1 {
        return DVec2::splat(0.5);
    }
    let [hx, hy] = pcg2d([index, k]);
    // 24 bits of each lane: exact in f32 as in f64.
    let jitter = DVec2::new(f64::from(hx >> 8), f64::from(hy >> 8)) / f64::from(1u32 << 24);
    let stratum = DVec2::new(f64::from(k % side), f64::from(k / side));
    (stratum + jitter) / f64::from(side)
}

/// The side of the sample grid for `spp` samples per pixel: a square of 1 to
/// `MAX_SAMPLES_PER_SIDE`², else an error naming the choices.
pub fn samples_per_side(spp: u32) -> Result<u32> {
    let side = (1..=MAX_SAMPLES_PER_SIDE).find(|s| s * s == spp);
    side.ok_or_else(|| {
        Error::Option(format!(
            "{spp} samples per pixel: samples are stratified on an s × s grid, so spp must \
             be a square from 1 to {} (1, 4, 9, 16, ...)",
            MAX_SAMPLES_PER_SIDE * MAX_SAMPLES_PER_SIDE
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every sample lies in its own stratum, and the strata tile the pixel.
    #[test]
    fn samples_are_stratified() {
        for side in [2, 3, 4] {
            for index in [0, 1, 77, 123_456] {
                for k in 0..side * side {
                    let p = sample_offset(index, k, side) * f64::from(side);
                    assert_eq!(
                        (p.x.floor() as u32, p.y.floor() as u32),
                        (k % side, k / side),
                        "side {side}, pixel {index}, sample {k}"
                    );
                }
            }
        }
        assert_eq!(sample_offset(5, 0, 1), DVec2::splat(0.5));
        // Different pixels jitter differently.
        assert_ne!(sample_offset(1, 0, 2), sample_offset(2, 0, 2));
    }

    #[test]
    fn spp_must_be_a_square() {
        assert_eq!(samples_per_side(1).unwrap(), 1);
        assert_eq!(samples_per_side(16).unwrap(), 4);
        for bad in [0, 2, 8, 257, 1024] {
            let message = samples_per_side(bad).unwrap_err().to_string();
            assert!(message.contains("must be a square"), "{message}");
        }
    }
}
