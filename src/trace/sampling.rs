//! Where a pixel's samples go, as `wgsl/sampling.wgsl` places them (its twin; the f64
//! reference renders the same samples, and a test holds the GPU to it).
//!
//! The s² samples are a rotated grid: cut the pixel into s² × s² cells; the sample of stratum
//! (x, y) (an s × s block of cells) sits at the centre of the block's cell (r, r) with
//! r = (y − x) mod s. That is the rank-1 lattice with generator (1, s + 1) over s² points,
//! shifted by half a cell: one sample in each stratum (stratified) and in each row and column
//! of cells (n-rooks: Shirley 1991), the "rotated grid" of real-time anti-aliasing
//! (Akenine-Möller et al., "Real-Time Rendering", 4th ed., section 5.4.2; rank-1 lattices in
//! image synthesis: Dammertz and Keller 2008). Each pixel takes one of 2s such arrangements,
//! hashed from it: the lattice moved by whole strata (wrapping around), mirrored or not, so
//! neighbouring pixels' errors do not line up.
//!
//! Why not jittered samples (Mitchell 1987; PBRT 4th ed. §8.5), as until 2026-11: where an
//! edge crosses a stratum, a sample at its cell's centre errs by the midpoint rule's error,
//! a jittered one by a coin toss; and the samples' mean is the pixel's centre, so colour that
//! changes linearly across the pixel is averaged exactly. Over straight edges through a pixel
//! the lattice has about 0.6 times jitter's expected squared coverage error (the test below);
//! in rendered images 0.42 to 0.93 times the MSE at equal rays on the shared scenes (the
//! book's "Speed against error"). Each row and column of cells holding a sample keeps a thin
//! line along the pixel grid from slipping between the samples, as it slips between the
//! centres of a plain s × s grid.
//!
//! 4 × 4 samples are a nested pattern instead ([`NESTED_SAMPLES`]): its first four are the
//! 2 × 2 lattice's, so adaptive sampling's estimate (2 × 2 samples) is the start of its
//! supersampling (16), which takes the other 12 (`trace::AdaptivePass`). No rank-1 lattice of
//! 16 holds the 2 × 2 one (its points sit on the edges of the 16 × 16 cells), so the other 12
//! were searched for: one in each free stratum and free row and column of cells, two thirds of
//! the way into its cell (which puts the mean at the centre), scored by simulated annealing on
//! the squared coverage error of 4,000 random straight edges, each pixel taking one of the 32
//! arrangements (transposed, mirrored, moved by quarter and half pixels: each keeps both the
//! 2 × 2 and the 4 × 4 strata filled). On 2,000 other random edges its error is 0.96 times the
//! lattice's; on gratings of up to 1, 2 and 4 cycles a pixel 1.02, 0.93 and 0.99 times (a
//! search scored on this module's test edges alone fitted them, 0.91 times the lattice there,
//! and lost elsewhere: 1.05 on the other edges).

use glam::DVec2;

use crate::error::{Error, Result};
use crate::shared::{MAX_SAMPLES_PER_SIDE, NESTED_SAMPLES, NESTED_SIDE, NESTED_UNITS};

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

/// Sample `k` of the `side` × `side` samples of pixel `index` (row-major by stratum, but for
/// the nested pattern's: see `nested_offset`): its offset from the pixel's top-left corner,
/// in (0, 1)². With one sample, the centre.
pub fn sample_offset(index: u32, k: u32, side: u32) -> DVec2 {
    let hash = pcg2d([index, 0]);
    if side == NESTED_SIDE || 2 * side == NESTED_SIDE {
        return nested_offset(k, hash);
    }
    let [hx, hy] = hash;
    let (x, y) = (k % side, k / side);
    let shift = hy % side;
    let cell = if hx & 1 == 1 {
        let r = (y + x + shift) % side;
        (side - 1 - r, r)
    } else {
        let r = (y + side - x + shift) % side;
        (r, r)
    };
    let cells = f64::from(side * side);
    DVec2::new(
        f64::from(x * side + cell.0) + 0.5,
        f64::from(y * side + cell.1) + 0.5,
    ) / cells
}

/// Entry `j` of [`NESTED_SAMPLES`] in the arrangement that `hash` picks, in 48ths of a pixel:
/// transposed or not, mirrored left to right or not, and moved (wrapping around) by a quarter
/// of a pixel along the diagonal 0 to 3 times and by half a pixel across or not, which keep
/// both the 2 × 2 and the 4 × 4 strata filled.
fn nested_point(j: usize, [hx, hy]: [u32; 2]) -> [u32; 2] {
    let [mut x, mut y] = NESTED_SAMPLES[j];
    if hx & 2 != 0 {
        std::mem::swap(&mut x, &mut y);
    }
    if hx & 1 != 0 {
        x = NESTED_UNITS - x;
    }
    let quarter = NESTED_UNITS / 4;
    let (diagonal, across) = (quarter * (hy % 4), 2 * quarter * (hy / 4 % 2));
    [
        (x + diagonal + across) % NESTED_UNITS,
        (y + diagonal) % NESTED_UNITS,
    ]
}

/// Sample `k` of the nested pattern in the arrangement that `hash` picks: the first four are
/// the 2 × 2 samples, in the order of their 2 × 2 strata (row-major), then the others in
/// [`NESTED_SAMPLES`]'s order.
fn nested_offset(k: u32, hash: [u32; 2]) -> DVec2 {
    let half = NESTED_UNITS / 2;
    let [x, y] = if k < 4 {
        (0..4)
            .map(|j| nested_point(j, hash))
            .find(|&[x, y]| x / half + 2 * (y / half) == k)
            .expect("the first four nested samples fill the 2 × 2 strata")
    } else {
        nested_point(k as usize, hash)
    };
    DVec2::new(f64::from(x), f64::from(y)) / f64::from(NESTED_UNITS)
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

    /// Every sample lies in its own stratum and alone in its row and column of cells, at the
    /// cell's centre; the samples' mean is the pixel's centre; with one sample, the centre.
    #[test]
    fn samples_are_stratified_n_rooks_and_centred() {
        for side in (1..=MAX_SAMPLES_PER_SIDE).filter(|&s| s != NESTED_SIDE) {
            let cells = side * side;
            for index in [0, 1, 77, 123_456, u32::MAX] {
                let (mut columns, mut rows) = (vec![0; cells as usize], vec![0; cells as usize]);
                let mut sum = DVec2::ZERO;
                for k in 0..cells {
                    let p = sample_offset(index, k, side);
                    let at = format!("side {side}, pixel {index}, sample {k}");
                    let stratum = p * f64::from(side);
                    assert_eq!(
                        (stratum.x.floor() as u32, stratum.y.floor() as u32),
                        (k % side, k / side),
                        "{at}"
                    );
                    let cell = p * f64::from(cells);
                    let off_centre = (cell.fract() - DVec2::splat(0.5)).abs().max_element();
                    assert!(off_centre < 1e-9, "{at}: {cell}");
                    columns[cell.x as usize] += 1;
                    rows[cell.y as usize] += 1;
                    sum += p;
                }
                assert!(columns.iter().chain(&rows).all(|&n| n == 1), "side {side}");
                let mean = sum / f64::from(cells);
                assert!(
                    (mean - DVec2::splat(0.5)).abs().max_element() < 1e-12,
                    "{mean}"
                );
            }
        }
        assert_eq!(sample_offset(5, 0, 1), DVec2::splat(0.5));
    }

    /// The nested pattern: its first four samples are the 2 × 2 pattern's, bit for bit (so
    /// adaptive sampling's estimate is the start of its supersampling); all sixteen fill the
    /// 4 × 4 strata, one each, with their mean at the pixel's centre; and along either axis
    /// no two lie closer than a third of a cell of the 16 × 16 or leave a gap wider than
    /// five thirds of one (n-rooks up to the 2 × 2 samples' place on cell edges).
    #[test]
    fn nested_samples_start_with_the_2x2_pattern() {
        let cells = f64::from(NESTED_SIDE * NESTED_SIDE);
        for index in (0..64).chain([123_456, u32::MAX]) {
            let samples: Vec<DVec2> = (0..cells as u32)
                .map(|k| sample_offset(index, k, NESTED_SIDE))
                .collect();
            for (k, p) in samples.iter().take(4).enumerate() {
                assert_eq!(
                    *p,
                    sample_offset(index, k as u32, 2),
                    "pixel {index}, sample {k}"
                );
            }
            let strata: std::collections::HashSet<[u32; 2]> = samples
                .iter()
                .map(|p| {
                    (*p * f64::from(NESTED_SIDE))
                        .floor()
                        .to_array()
                        .map(|c| c as u32)
                })
                .collect();
            assert_eq!(strata.len(), 16, "pixel {index}");
            let mean = samples.iter().sum::<DVec2>() / cells;
            assert!(
                (mean - DVec2::splat(0.5)).abs().max_element() < 1e-12,
                "{mean}"
            );
            for axis in 0..2 {
                let mut at: Vec<f64> = samples.iter().map(|p| p[axis] * cells).collect();
                at.sort_by(f64::total_cmp);
                for (i, a) in at.iter().enumerate() {
                    let gap = (at.get(i + 1).copied().unwrap_or(at[0] + cells) - a).abs();
                    assert!(
                        (1.0 / 3.0 - 1e-9..=5.0 / 3.0 + 1e-9).contains(&gap),
                        "pixel {index}, axis {axis}: {at:?}"
                    );
                }
            }
        }
    }

    /// Pixels take every arrangement: the lattice's 2 × side (moved by 0 to side − 1 strata,
    /// mirrored or not); the nested pattern's 32 (transposed, mirrored, moved 8 ways), whose
    /// first four are the 2 × 2 lattice's 4 (the rotated grid has fewer symmetries to spare).
    /// So neighbours' errors do not line up.
    #[test]
    fn pixels_take_every_arrangement() {
        for (side, arrangements) in [(2, 4), (3, 6), (4, 32), (5, 10)] {
            let patterns: std::collections::HashSet<Vec<[u64; 2]>> = (0..1024)
                .map(|index| {
                    (0..side * side)
                        .map(|k| sample_offset(index, k, side).to_array().map(f64::to_bits))
                        .collect()
                })
                .collect();
            assert_eq!(patterns.len(), arrangements, "side {side}");
        }
    }

    /// The area of the square with corner `corner` and side `size` on the side of the line
    /// `normal · p = offset` where `normal · p <= offset` (Sutherland-Hodgman clipping, then
    /// the shoelace formula).
    fn area_inside(corner: DVec2, size: f64, normal: DVec2, offset: f64) -> f64 {
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y].map(|c| corner + c * size);
        let mut clipped = Vec::new();
        for (i, &a) in square.iter().enumerate() {
            let b = square[(i + 1) % 4];
            let (da, db) = (normal.dot(a) - offset, normal.dot(b) - offset);
            if da <= 0.0 {
                clipped.push(a);
            }
            if (da < 0.0) != (db < 0.0) && da != db {
                clipped.push(a + (b - a) * (da / (da - db)));
            }
        }
        let twice: f64 = (0..clipped.len())
            .map(|i| clipped[i].perp_dot(clipped[(i + 1) % clipped.len()]))
            .sum();
        twice.abs() / 2.0
    }

    /// What the pattern is for: over straight edges through a pixel (90 directions × 41
    /// offsets, each in a different pixel, so every arrangement takes its turn) the share of
    /// samples inside misses the share of area inside by a mean square well below jittered
    /// stratified sampling's expected one, Σ p(1 − p) / N² over the strata (p a stratum's
    /// share inside: its sample falls inside with that chance). Measured 0.60 to 0.65 of it
    /// for 2 × 2 to 8 × 8 (a plain grid of strata centres: 0.42 to 0.46); jitter would give 1.
    #[test]
    fn edges_are_estimated_better_than_by_jitter() {
        for side in [2, 3, 4, 8] {
            let n = side * side;
            let (mut lattice, mut jitter) = (0.0, 0.0);
            for i in 0..90u32 {
                let angle = (f64::from(i) + 0.5) * std::f64::consts::TAU / 90.0;
                let normal = DVec2::from_angle(angle);
                for j in 0..41u32 {
                    // Lines through points from (0.15, 0.15) to (0.85, 0.85).
                    let through = DVec2::splat(0.15 + 0.7 * f64::from(j) / 40.0);
                    let offset = normal.dot(through);
                    let area = area_inside(DVec2::ZERO, 1.0, normal, offset);
                    let index = i * 41 + j;
                    let inside = (0..n)
                        .filter(|&k| normal.dot(sample_offset(index, k, side)) <= offset)
                        .count();
                    lattice += (inside as f64 / f64::from(n) - area).powi(2);
                    let stratum = 1.0 / f64::from(side);
                    for k in 0..n {
                        let corner = DVec2::new(f64::from(k % side), f64::from(k / side));
                        let p =
                            area_inside(corner * stratum, stratum, normal, offset) * f64::from(n);
                        jitter += p * (1.0 - p) / f64::from(n * n);
                    }
                }
            }
            let ratio = lattice / jitter;
            assert!(
                ratio < 0.75,
                "side {side}: {ratio:.3} of jitter's squared error"
            );
        }
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
