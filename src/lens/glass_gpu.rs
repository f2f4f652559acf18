//! A prescription as the GPU traces it per ray (`wgsl/glass.wgsl`): its surfaces, and the
//! bounds of its exit pupil seen from each radial place on the film, so that the rays a pixel
//! sends toward the lens are not wasted on the housing (pbrt's `RealisticCamera` precomputes
//! such bounds in radial bins: Pharr, Jakob and Humphreys, "Physically Based Rendering", 3rd
//! ed., section 6.4.5).
//!
//! A film point's ray aims at a point drawn uniformly in its bin's ellipse on the plane of the
//! rear vertex and is traced out through the glass; what gets through carries the weight
//! `cos⁴θ · A / z²` (the irradiance a point of the film gets from a patch of area `A` at
//! axial distance `z` is `L cos⁴θ dA / z²`), divided by the same estimate's mean at the film's
//! centre, so a uniform white scene is 1 at the centre of the image: vignetting (the pupil's
//! share that gets through, and the cos⁴ falloff) darkens the rest as the glass says.
//!
//! A point of the ellipse whose ray the glass stops is drawn again (rejection sampling), and
//! what gets through is weighted by the share of the ellipse that does from that film place
//! (`GlassParams::shares`, found here once): the expected value is the same, but a sample is
//! never black for being stopped, so the image is not speckled by the housing (Bernoulli noise
//! of the share that gets through, 3 to 15 % of samples stopped through Muller's fisheye).

use bytemuck::{Pod, Zeroable};
use glam::{DVec2, DVec3};

use super::prescription::{Prescription, Ray};
use crate::error::LensError;
use crate::shared::GLASS_SIZES;

/// The most surfaces the GPU's glass takes.
pub const GLASS_SURFACES: u32 = GLASS_SIZES[0].1;
/// Radial bins of the exit pupil, from the film's centre to its corners.
pub const PUPIL_BINS: u32 = GLASS_SIZES[1].1;
/// Scene units (metres) per millimetre of the lens.
const METRES_PER_MM: f64 = 1e-3;
/// Rays a side of the grid each bin's bounds are found with, over half the search square (the
/// lens is symmetric about the plane through the film point and the axis).
const PUPIL_GRID: usize = 32;
/// Film places a bin's pupil is found at: its inner edge, middle and outer edge.
const PUPIL_FILM_POINTS: usize = 3;
/// How the share of a bin's ellipse that gets through is measured (`passing_share`): rows
/// across its upper half (the pupil seen from a film point on the +x axis is symmetric in y),
/// points along each row that find where rays get through, and bisection steps that find
/// each such run's ends (to 2⁻¹² of the row's length), so the share is good to about 1e-4
/// (the rows' midpoint rule) where a grid of points would be off by its cells along the edge.
const SHARE_ROWS: u32 = 32;
const SHARE_POINTS: u32 = 16;
const SHARE_BISECTIONS: u32 = 12;
/// Directions (over half a turn) along which the pupil's edge is found, and the bisection
/// steps that find it (to 2⁻²⁴ of the search square: far below a grid cell).
const PUPIL_ANGLES: u32 = 64;
const PUPIL_BISECTIONS: u32 = 24;

/// A prescription on the film as `wgsl/glass.wgsl` reads it (4,656 bytes; a test checks the
/// layout against naga's). Lens frame: mm, z from the front vertex toward the film.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GlassParams {
    /// Surfaces, pupil bins, channels traced apart (3 where the glass disperses, else 1), 0.
    pub counts: [u32; 4],
    /// The film's z, the rear vertex's z, the film's mm per pixel, the film radius the bins
    /// span (the image's half diagonal).
    pub film: [f32; 4],
    /// The weights' normalisation per channel (1 / the centre's `∫ cos⁴θ / z² dA`: red,
    /// green, blue), metres per mm.
    pub scale: [f32; 4],
    /// Per surface, front to back: radius (0: the stop), vertex z, the squared half aperture,
    /// 0.
    pub surfaces: [[f32; 4]; GLASS_SURFACES as usize],
    /// Per surface: the index behind it in the red, green and blue channels (the C, d and F
    /// lines; the same without dispersion), 0.
    pub indices: [[f32; 4]; GLASS_SURFACES as usize],
    /// Per bin: the ellipse on the rear vertex's plane that holds the exit pupil seen from a
    /// film point on the +x axis in every channel (centre x, centre y, semi-axes x and y;
    /// zero where no ray gets through).
    pub pupil: [[f32; 4]; PUPIL_BINS as usize],
    /// Per bin and channel (red, green, blue, 0): the share of its ellipse (by area, as the
    /// kernel draws points) whose rays get through from its inner edge (`shares[2 * bin]`)
    /// and its outer edge (`shares[2 * bin + 1]`) on the film, interpolated between.
    pub shares: [[f32; 4]; 2 * PUPIL_BINS as usize],
}

const _: () = assert!(size_of::<GlassParams>() == 48 + 16 * (32 + 32 + 64 + 128));

impl GlassParams {
    /// The glass of `p` with its film `film_mm` behind the rear vertex, on an image of `width`
    /// × `height` pixels `sensor_mm` wide on the film (see `lens::glass::GlassLens`).
    pub fn new(
        p: &Prescription,
        film_mm: f64,
        sensor_mm: f64,
        (width, height): (u32, u32),
    ) -> Result<Self, LensError> {
        let count = p.surfaces().len();
        if count > GLASS_SURFACES as usize {
            return Err(LensError::Spec {
                spec: "prescription".into(),
                reason: format!(
                    "{count} surfaces: the GPU traces at most {GLASS_SURFACES} (use rays=fit \
                     for its fitted model)"
                ),
            });
        }
        let channels = channels(p);
        let pitch = sensor_mm / f64::from(width);
        let film_z = p.rear_vertex() + film_mm;
        let reach = 0.5 * pitch * f64::from(width).hypot(f64::from(height));
        let bins = exit_pupil(&channels, film_z, reach);
        // Each channel's normalisation; without dispersion the one lens's is every channel's.
        let mut scale = [0.0, 0.0, 0.0, METRES_PER_MM as f32];
        for (c, lens) in channels.iter().enumerate() {
            let centre = centre_mean(lens, film_z, bins[0]);
            if centre.is_nan() || centre <= 0.0 {
                return Err(LensError::Spec {
                    spec: "prescription".into(),
                    reason: "no ray from the film's centre gets through the glass".into(),
                });
            }
            scale[c] = (1.0 / centre) as f32;
        }
        let first = scale[0];
        scale[channels.len()..3].fill(first);
        let mut out = Self {
            counts: [count as u32, PUPIL_BINS, channels.len() as u32, 0],
            film: [
                film_z as f32,
                p.rear_vertex() as f32,
                pitch as f32,
                reach as f32,
            ],
            scale,
            ..Zeroable::zeroed()
        };
        for (k, s) in p.surfaces().iter().enumerate() {
            out.surfaces[k] = [
                s.radius as f32,
                p.vertex(k) as f32,
                (0.25 * s.aperture * s.aperture) as f32,
                0.0,
            ];
            let index = |c: usize| channels[c % channels.len()].surfaces()[k].index as f32;
            out.indices[k] = [index(0), index(1), index(2), 0.0];
        }
        for (bin, b) in bins.iter().enumerate() {
            out.pupil[bin] = b.map(|v| v as f32);
            for edge in 0..2 {
                let radius = (bin + edge) as f64 / f64::from(PUPIL_BINS) * reach;
                let share = |c: usize| {
                    let lens = &channels[c % channels.len()];
                    passing_share(lens, DVec3::new(radius, 0.0, film_z), *b) as f32
                };
                out.shares[2 * bin + edge] = [share(0), share(1), share(2), 0.0];
            }
        }
        Ok(out)
    }

    /// The same glass on an image `factor` times larger each way (the same film).
    pub fn scaled(&self, factor: u32) -> Self {
        let mut out = *self;
        out.film[2] /= factor as f32;
        out
    }
}

/// The lens in each channel traced apart: red, green and blue (the C, d and F lines) where it
/// disperses, else the lens alone.
fn channels(p: &Prescription) -> Vec<Prescription> {
    use super::prescription::{LINE_C_NM, LINE_D_NM, LINE_F_NM};
    if !p.is_dispersive() {
        return vec![p.clone()];
    }
    [LINE_C_NM, LINE_D_NM, LINE_F_NM]
        .map(|nm| p.at_wavelength(nm))
        .to_vec()
}

/// The exit pupil of `lenses` (one lens in its channels) seen from film points `film_z` from
/// the front vertex on the +x axis, in
/// [`PUPIL_BINS`] bins out to `reach` mm, as an ellipse on the rear vertex's plane per bin
/// (centre x, centre y, semi-axes x and y; zero semi-axes where no ray gets through): a grid
/// over 1.5 times the rear aperture (as pbrt searches) finds the points that get through from
/// some film point of the bin, bisection along rays from their centre finds the edge, and the
/// ellipse holds both (grown by 0.1 %). A round pupil fills its ellipse, a vignetted cat's eye
/// most of it, where either fills π/4 or less of a bounding box: few rays are lost to the
/// housing, and those at the rim.
fn exit_pupil(lenses: &[Prescription], film_z: f64, reach: f64) -> Vec<[f64; 4]> {
    let p = &lenses[0];
    let rear = p.surfaces().last().expect("a prescription has surfaces");
    let half = 0.75 * rear.aperture;
    let cell = 2.0 * half / PUPIL_GRID as f64;
    let plane = p.rear_vertex();
    (0..PUPIL_BINS)
        .map(|bin| {
            // Each channel's lens from each film place of the bin.
            let sources: Vec<(&Prescription, DVec3)> = (0..PUPIL_FILM_POINTS)
                .flat_map(|f| {
                    let t = (f64::from(bin) + f as f64 / (PUPIL_FILM_POINTS - 1) as f64)
                        / f64::from(PUPIL_BINS);
                    lenses
                        .iter()
                        .map(move |lens| (lens, DVec3::new(t * reach, 0.0, film_z)))
                })
                .collect();
            // Whether each cell's centre passes from some source (y ≥ 0: the pupil is
            // symmetric in y).
            let centre_of = |k: usize| {
                let (i, j) = (k % PUPIL_GRID, PUPIL_GRID / 2 + k / PUPIL_GRID);
                DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * cell - half
            };
            let cells: Vec<DVec2> = (0..PUPIL_GRID * PUPIL_GRID / 2)
                .map(centre_of)
                .filter(|at| {
                    sources
                        .iter()
                        .any(|&(lens, film)| passes(lens, film, at.extend(plane)))
                })
                .collect();
            let Some(x_lo) = cells.iter().map(|c| c.x).reduce(f64::min) else {
                return [0.0; 4];
            };
            let x_hi = cells.iter().map(|c| c.x).fold(f64::MIN, f64::max);
            let centre = DVec2::new(0.5 * (x_lo + x_hi), 0.0);
            // The pupil's edge from its centre, by bisection along rays of angles 0 to π (the
            // pupil is symmetric in y and, round or a cat's eye, star-shaped about its centre).
            let mut edge: Vec<DVec2> = cells.clone();
            for &(lens, film) in &sources {
                if !passes(lens, film, centre.extend(plane)) {
                    continue;
                }
                for a in 0..=PUPIL_ANGLES {
                    let phi = std::f64::consts::PI * f64::from(a) / f64::from(PUPIL_ANGLES);
                    let along = DVec2::new(phi.cos(), phi.sin());
                    let (mut inside, mut outside) = (0.0, 4.0 * half);
                    for _ in 0..PUPIL_BISECTIONS {
                        let mid = 0.5 * (inside + outside);
                        if passes(lens, film, (centre + mid * along).extend(plane)) {
                            inside = mid;
                        } else {
                            outside = mid;
                        }
                    }
                    edge.push(centre + outside * along);
                }
            }
            // The ellipse of the edge's extents about the centre, grown to hold every point.
            let semi = edge
                .iter()
                .map(|e| (*e - centre).abs())
                .fold(DVec2::splat(1e-9), DVec2::max);
            let scale = edge
                .iter()
                .map(|e| ((*e - centre) / semi).length())
                .fold(1.0, f64::max)
                * (1.0 + 1e-3);
            [centre.x, centre.y, scale * semi.x, scale * semi.y]
        })
        .collect()
}

/// The share of `ellipse` (centre x, centre y, semi-axes x and y on the rear vertex's plane;
/// uniform by area, as the kernel draws its points) whose rays from `film` (on the +x axis)
/// get through `p`, 0 for an ellipse with no area (no ray gets through from its bin): along
/// each of [`SHARE_ROWS`] rows over its upper half, [`SHARE_POINTS`] points find the runs of
/// the chord whose rays get through, and bisection finds each run's ends.
fn passing_share(p: &Prescription, film: DVec3, ellipse: [f64; 4]) -> f64 {
    let [cx, cy, a, b] = ellipse;
    if a <= 0.0 || b <= 0.0 {
        return 0.0;
    }
    let through = |x: f64, y: f64| passes(p, film, DVec3::new(x, y, p.rear_vertex()));
    // Where along a row, between a point whose ray is stopped and one whose gets through,
    // the run's end lies.
    let end = |y: f64, mut stopped: f64, mut passed: f64| {
        for _ in 0..SHARE_BISECTIONS {
            let mid = 0.5 * (stopped + passed);
            if through(mid, y) {
                passed = mid;
            } else {
                stopped = mid;
            }
        }
        0.5 * (stopped + passed)
    };
    let mut area = 0.0;
    for row in 0..SHARE_ROWS {
        let v = (f64::from(row) + 0.5) / f64::from(SHARE_ROWS);
        let (y, half) = (cy + v * b, a * (1.0 - v * v).sqrt());
        let (first, step) = (cx - half, 2.0 * half / f64::from(SHARE_POINTS));
        // The points, and the chord's ends beyond them (outside the pupil: the ellipse holds it).
        let at = |i: u32| first + (f64::from(i) + 0.5) * step;
        let mut start = None;
        for i in 0..=SHARE_POINTS {
            let inside = i < SHARE_POINTS && through(at(i), y);
            match (start, inside) {
                (None, true) => {
                    let before = if i == 0 { first } else { at(i - 1) };
                    start = Some(end(y, before, at(i)));
                }
                (Some(from), false) => {
                    let after = if i == SHARE_POINTS { cx + half } else { at(i) };
                    area += end(y, after, at(i - 1)) - from;
                    start = None;
                }
                _ => {}
            }
        }
    }
    // Both halves: each row stands for a strip b / SHARE_ROWS high, mirrored below the axis.
    (2.0 * area * b / f64::from(SHARE_ROWS) / (std::f64::consts::PI * a * b)).min(1.0)
}

/// Whether the ray from `film` toward `target` gets out through the glass.
fn passes(p: &Prescription, film: DVec3, target: DVec3) -> bool {
    let ray = Ray {
        origin: film,
        direction: (target - film).normalize(),
    };
    p.trace_from_film(ray).is_ok()
}

/// The film centre's `∫ cos⁴θ / z² dA` over the rear vertex's plane, rays that do not get
/// through counting 0 (the mean the weights are divided by), over `ellipse`'s bounding box,
/// which holds every ray that gets through.
fn centre_mean(p: &Prescription, film_z: f64, ellipse: [f64; 4]) -> f64 {
    let lo = DVec2::new(ellipse[0] - ellipse[2], ellipse[1] - ellipse[3]);
    let size = 2.0 * DVec2::new(ellipse[2], ellipse[3]);
    irradiance(p, DVec3::new(0.0, 0.0, film_z), lo, size)
}

/// `∫ cos⁴θ / z² dA` at `film` over the rectangle from `lo` of `size` on the rear vertex's
/// plane, rays that do not get through counting 0: a 256² grid's midpoint sum.
fn irradiance(p: &Prescription, film: DVec3, lo: DVec2, size: DVec2) -> f64 {
    let n = 256;
    let z = film.z - p.rear_vertex();
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let at = lo + DVec2::new(i as f64 + 0.5, j as f64 + 0.5) / n as f64 * size;
            let target = at.extend(p.rear_vertex());
            if passes(p, film, target) {
                let cos = z / (target - film).length();
                sum += cos.powi(4);
            }
        }
    }
    sum / (n * n) as f64 * size.x * size.y / (z * z)
}

/// The irradiance of a film `film_mm` behind the rear vertex of `p`, `radius_mm` from its
/// centre, relative to the centre's, for a uniform
/// scene: vignetting by the glass (the share of the pupil that gets through) and the cos⁴
/// falloff, integrated without the exit-pupil ellipses that rendering samples (an
/// independent check of them): a 64² grid over 1.5 times the rear aperture finds where rays
/// get through, a 256² grid over that box (grown by a coarse cell) integrates.
pub fn relative_illumination(p: &Prescription, film_mm: f64, radius_mm: f64) -> f64 {
    let film_z = p.rear_vertex() + film_mm;
    let at = |film: DVec3| {
        let half = 0.75
            * p.surfaces()
                .last()
                .expect("a prescription has surfaces")
                .aperture;
        let cell = 2.0 * half / 64.0;
        let (mut lo, mut hi) = (DVec2::MAX, DVec2::MIN);
        for i in 0..64 {
            for j in 0..64 {
                let point = DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * cell - half;
                if passes(p, film, point.extend(p.rear_vertex())) {
                    (lo, hi) = (lo.min(point), hi.max(point));
                }
            }
        }
        if lo.x > hi.x {
            return 0.0;
        }
        irradiance(p, film, lo - cell, hi - lo + 2.0 * cell)
    };
    at(DVec3::new(radius_mm, 0.0, film_z)) / at(DVec3::new(0.0, 0.0, film_z))
}

#[cfg(test)]
mod tests {
    use std::mem::offset_of;

    use super::GlassParams;
    use crate::shader::assert_wgsl_layout;

    /// `GlassParams` in Rust and WGSL have the same size and field offsets (naga's layout).
    #[test]
    fn glass_params_layout_matches_wgsl() {
        assert_wgsl_layout(
            "glass",
            "GlassParams",
            size_of::<GlassParams>(),
            &[
                ("counts", offset_of!(GlassParams, counts)),
                ("film", offset_of!(GlassParams, film)),
                ("scale", offset_of!(GlassParams, scale)),
                ("surfaces", offset_of!(GlassParams, surfaces)),
                ("indices", offset_of!(GlassParams, indices)),
                ("pupil", offset_of!(GlassParams, pupil)),
                ("shares", offset_of!(GlassParams, shares)),
            ],
        );
    }
}
