//! The cube's pure geometry: which face and where on it a direction lands, bordered faces and
//! their bilinear lookup, the part of each face a lens reaches, and the camera a face is
//! rendered through. The face table itself ([`FACES`]) is in [`crate::shared`], since WGSL
//! reads it too; `wgsl/cube.wgsl` is the GPU twin of [`face_uv`], and a test checks that both
//! pick the same face and UV.

use glam::{DVec2, DVec3, Vec2, Vec3};

use crate::error::Result;
use crate::lens::{ClassicLens, ImageSize, LensCamera, LensModel};
use crate::shared::FACES;

/// The face a direction lands on, and its UV in [0, 1]² (u right, v down), in f32 as the GPU
/// computes it. The axis of largest magnitude wins; exact ties go to x over y over z, and a
/// zero component counts as positive. The zero vector maps to the centre of `+z`.
pub fn face_uv(d: Vec3) -> (u32, Vec2) {
    let a = d.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    if a[axis] == 0.0 {
        return (4, Vec2::splat(0.5));
    }
    let face = 2 * axis as u32 + u32::from(d[axis] < 0.0);
    let f = &FACES[face as usize];
    let major = d.dot(f.forward);
    let uv = (Vec2::new(d.dot(f.right), d.dot(f.down)) / major + 1.0) * 0.5;
    (face, uv)
}

/// Faces with a one-texel border: a face of `size` texels is stored as `(size + 2)²` texels,
/// the border holding the neighbouring faces' samples (rendered as directions just past the
/// edge), so that bilinear filtering near a seam reads real neighbours, never clamped ones.
pub fn bordered(size: u32) -> u32 {
    size + 2
}

/// The rectilinear focal length (in the lens module's normalized units, half-width = 1) of a
/// bordered face image: its inner `size` texels span exactly 90°.
pub fn bordered_focal(size: u32) -> f64 {
    f64::from(size) / f64::from(bordered(size))
}

/// Bilinear lookup of a bordered face at `uv`, as `wgsl/cube.wgsl` does: texels are
/// `texels[face][row][column]` of side `size + 2`, centres at `(i + 0.5) / size` past the border.
pub fn sample_bordered(texels: &[[f32; 4]], size: u32, face: u32, uv: Vec2) -> [f32; 4] {
    let side = bordered(size) as usize;
    let st = uv * size as f32 + 0.5;
    let base = st.floor();
    let f = st - base;
    let x = (base.x.max(0.0) as usize).min(side - 2);
    let y = (base.y.max(0.0) as usize).min(side - 2);
    let at = |x: usize, y: usize| texels[(face as usize * side + y) * side + x];
    let mix = |a: [f32; 4], b: [f32; 4], t: f32| std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t);
    let top = mix(at(x, y), at(x + 1, y), f.x);
    let bottom = mix(at(x, y + 1), at(x + 1, y + 1), f.x);
    mix(top, bottom, f.y)
}

/// Lookups across a pixel at most in the resampler (`wgsl/cube_sample.wgsl`'s `MOST_TAPS`).
pub const MOST_TAPS: u32 = 8;

/// Face texels across the pixel whose ray is `d` and whose neighbours' rays are `steps` away
/// ([`LensCamera::steps`]), on `face`: the longer of the pixel's two sides there.
pub fn texels_across(size: u32, face: u32, d: Vec3, steps: [Vec3; 2]) -> f32 {
    let f = &FACES[face as usize];
    let on_face = |q: Vec3| Vec2::new(q.dot(f.right), q.dot(f.down)) / q.dot(f.forward);
    let at = on_face(d);
    let longest = steps
        .iter()
        .map(|&s| (on_face(d + s) - at).length())
        .fold(0.0, f32::max);
    // Face coordinates span [-1, 1]: half the face's texels a unit.
    longest * 0.5 * size as f32
}

/// The directions the resampler reads for the pixel whose ray is `d` and whose neighbours'
/// are `steps` away, as `wgsl/cube_sample.wgsl` makes them: the centres of an n × n grid of
/// the pixel's square, n the face texels across it rounded, from 1 (its centre alone) to
/// [`MOST_TAPS`], moved from `d` along `steps`.
pub fn resample_taps(size: u32, d: Vec3, steps: [Vec3; 2]) -> impl Iterator<Item = Vec3> {
    let n = (texels_across(size, face_uv(d).0, d, steps).round() as u32).clamp(1, MOST_TAPS);
    (0..n * n).map(move |k| {
        let o = (Vec2::new((k % n) as f32, (k / n) as f32) + 0.5) / n as f32 - 0.5;
        d + steps[0] * o.x + steps[1] * o.y
    })
}

/// The resampler's colour of the pixel whose ray is `d` and whose neighbours' are `steps`
/// away (w = 1): the mean of the bilinear lookups at its [`resample_taps`].
pub fn resample(texels: &[[f32; 4]], size: u32, d: Vec3, steps: [Vec3; 2]) -> [f32; 4] {
    let mut sum = [0.0f32; 3];
    let mut taps = 0;
    for tap in resample_taps(size, d, steps) {
        let (face, uv) = face_uv(tap);
        let c = sample_bordered(texels, size, face, uv);
        sum.iter_mut().zip(c).for_each(|(s, c)| *s += c);
        taps += 1;
    }
    let taps = taps as f32;
    [sum[0] / taps, sum[1] / taps, sum[2] / taps, 1.0]
}

/// Every direction the resampler reads through `camera` from faces of `size` texels
/// ([`resample_taps`] of each pixel with a ray), for [`face_regions`].
pub fn resampled_directions(camera: &LensCamera, size: u32) -> impl Iterator<Item = DVec3> + '_ {
    let width = camera.size.width as usize;
    camera
        .directions()
        .into_iter()
        .enumerate()
        .flat_map(move |(i, d)| {
            d.into_iter().flat_map(move |d| {
                let pixel = DVec2::new((i % width) as f64 + 0.5, (i / width) as f64 + 0.5);
                let steps = camera.steps(pixel, d, 1.0).map(|s| s.as_vec3());
                resample_taps(size, d.as_vec3(), steps).map(|t| t.as_dvec3())
            })
        })
}

/// A rectangle of a bordered face, in texels: columns `x0..x1`, rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Region {
    /// Number of texels.
    pub fn texels(&self) -> u64 {
        u64::from(self.x1 - self.x0) * u64::from(self.y1 - self.y0)
    }
}

/// The part of each bordered face of `size` texels that sampling `directions` reads: the
/// bilinear footprints of every direction that lands on the face or within a small margin of
/// it, grown by one texel, so that the GPU's f32 directions (about 1e-7 rad from these f64
/// ones) never read a texel that was not rendered. `None` for faces nothing reaches.
pub fn face_regions(directions: impl IntoIterator<Item = DVec3>, size: u32) -> [Option<Region>; 6] {
    const MARGIN: f64 = 1e-4;
    let side = i64::from(bordered(size));
    let mut regions: [Option<Region>; 6] = [None; 6];
    for d in directions {
        for (i, f) in FACES.iter().enumerate() {
            let forward = d.dot(f.forward.as_dvec3());
            let (sc, tc) = (d.dot(f.right.as_dvec3()), d.dot(f.down.as_dvec3()));
            if forward <= 0.0 || forward * (1.0 + MARGIN) < sc.abs().max(tc.abs()) {
                continue;
            }
            // As `sample_bordered`: texels floor(st) and floor(st) + 1, clamped, then ±1.
            let texel = |c: f64| {
                let st = ((c / forward + 1.0) * 0.5) * f64::from(size) + 0.5;
                let x = (st.floor() as i64).clamp(0, side - 2);
                ((x - 1).max(0) as u32, (x + 3).min(side) as u32)
            };
            let ((x0, x1), (y0, y1)) = (texel(sc), texel(tc));
            let r = regions[i].get_or_insert(Region { x0, y0, x1, y1 });
            *r = Region {
                x0: r.x0.min(x0),
                y0: r.y0.min(y0),
                x1: r.x1.max(x1),
                y1: r.y1.max(y1),
            };
        }
    }
    regions
}

/// The rectilinear camera of one bordered face of `size` inner texels, as the tracer renders
/// it: `(size + 2)²` pixels, 90° across the inner `size`.
pub fn face_camera(size: u32) -> Result<LensCamera> {
    let side = bordered(size);
    let lens = ClassicLens::new(LensModel::Rectilinear, bordered_focal(size))?;
    Ok(LensCamera::new(lens, ImageSize::new(side, side)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_are_rotations_and_uv_follows_the_axes() {
        for (i, f) in FACES.iter().enumerate() {
            let r = f.rotation();
            assert!((r.determinant() - 1.0).abs() < 1e-15, "{}", f.name);
            // The face's centre, and its right and down edges.
            assert_eq!(face_uv(f.forward), (i as u32, Vec2::splat(0.5)));
            let right = face_uv(f.forward + 0.5 * f.right);
            assert_eq!(right, (i as u32, Vec2::new(0.75, 0.5)), "{}", f.name);
            let down = face_uv(f.forward + 0.5 * f.down);
            assert_eq!(down, (i as u32, Vec2::new(0.5, 0.75)), "{}", f.name);
        }
        // The formula on +z.
        let d = Vec3::new(0.3, -0.2, 0.9);
        assert_eq!(face_uv(d), (4, (Vec2::new(d.x, d.y) / d.z + 1.0) * 0.5));
        // Ties: x over y over z, zero counts as positive.
        assert_eq!(face_uv(Vec3::new(1.0, 1.0, 1.0)).0, 0);
        assert_eq!(face_uv(Vec3::new(0.0, -1.0, 1.0)).0, 3);
        assert_eq!(face_uv(Vec3::new(-1.0, 1.0, 0.0)).0, 1);
        assert_eq!(face_uv(Vec3::ZERO), (4, Vec2::splat(0.5)));
    }

    #[test]
    fn bilinear_sampling_reads_the_border() {
        // A face of 2 texels (4 × 4 bordered) whose texel (x, y) holds x + 10 y: sampling is
        // exact for this linear function anywhere, the border included.
        let size = 2;
        let side = bordered(size) as usize;
        let texels: Vec<[f32; 4]> = (0..6 * side * side)
            .map(|i| {
                let (x, y) = ((i % side) as f32, ((i / side) % side) as f32);
                [x + 10.0 * y, 0.0, 0.0, 1.0]
            })
            .collect();
        for (u, v) in [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0), (0.1, 0.9), (0.75, 0.25)] {
            let s = sample_bordered(&texels, size, 3, Vec2::new(u, v));
            // Texel centre of bordered column x is at u = (x - 0.5) / size.
            let expected = (u * 2.0 + 0.5) + 10.0 * (v * 2.0 + 0.5);
            assert!(
                (s[0] - expected).abs() < 1e-5,
                "{u} {v}: {s:?} vs {expected}"
            );
        }
    }

    #[test]
    fn regions_follow_the_field_of_view() {
        let reached = |r: [Option<Region>; 6]| r.map(|r| r.is_some());
        // Straight ahead only: the centre of the front face, with its footprint.
        let ahead = face_regions([DVec3::Z], 8);
        assert_eq!(reached(ahead), [false, false, false, false, true, false]);
        assert_eq!(
            ahead[4],
            Some(Region {
                x0: 3,
                y0: 3,
                x1: 7,
                y1: 7
            })
        );
        // A hemisphere: all of the front face, the front half of each side face, never the
        // back face.
        let hemisphere = (0..=90).flat_map(|t| {
            (0..360).map(move |p| {
                let (t, p) = (f64::from(t).to_radians(), f64::from(p).to_radians());
                DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
            })
        });
        let size = 64;
        let r = face_regions(hemisphere, size);
        assert_eq!(reached(r), [true, true, true, true, true, false]);
        let side = bordered(size);
        assert_eq!(r[4].unwrap().texels(), u64::from(side * side));
        for i in 0..4 {
            let t = r[i].unwrap().texels() as f64 / f64::from(side * side);
            assert!((0.5..0.56).contains(&t), "face {}: {t}", FACES[i].name);
        }
    }
}
