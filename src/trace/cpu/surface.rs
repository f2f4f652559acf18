//! Shading helpers of the reference: the surface point a hit leaves, reflection, refraction's
//! Fresnel term, and texture lookups in linear colour.

use crate::scene::Texture;
use glam::{DVec2, DVec3};

pub(super) struct SurfacePoint {
    pub(super) position: DVec3,
    pub(super) geometric: DVec3,
    pub(super) normal: DVec3,
    pub(super) front: bool,
    pub(super) diffuse: DVec3,
    pub(super) specular: DVec3,
    pub(super) shininess: f64,
}

pub(super) fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - 2.0 * d.dot(n) * n
}

/// As `keep_side` in `wgsl/shade.wgsl`: `dir` kept on the `side` of the geometric surface
/// (1: where the ray came from; -1: beyond), at least `GRAZING_COSINE` off it.
pub(super) fn keep_side(dir: DVec3, geometric: DVec3, side: f64) -> DVec3 {
    let graze = f64::from(crate::shared::GRAZING_COSINE);
    let c = side * dir.dot(geometric);
    if c >= graze {
        return dir;
    }
    (dir + side * (graze - c) * geometric).normalize()
}

pub(super) fn fresnel(cos_i: f64, cos_t: f64, eta: f64) -> f64 {
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (rs * rs + rp * rp)
}

pub(in crate::trace) fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Trilinear: bilinear in the two mip levels around level of detail `lod` (`first`, then
/// `levels`), blended; the first alone at `lod` <= 0, the last beyond (as `wgsl/surface.wgsl`).
pub(super) fn trilinear(first: &Texture, levels: &[Texture], uv: DVec2, lod: f64) -> DVec3 {
    let l = lod.clamp(0.0, levels.len() as f64);
    let k = l.floor() as usize;
    let level = |k: usize| if k == 0 { first } else { &levels[k - 1] };
    let near = sample(level(k), uv);
    let f = l - k as f64;
    if f == 0.0 {
        return near;
    }
    near.lerp(sample(level(k + 1), uv), f)
}

/// Bilinear, repeat-wrapped, in linear space; v = 0 at the bottom (as `wgsl/surface.wgsl`).
pub(super) fn sample(t: &Texture, uv: DVec2) -> DVec3 {
    let (w, h) = (i64::from(t.width), i64::from(t.height));
    let texel = |x: i64, y: i64| {
        let (x, y) = (x.rem_euclid(w) as usize, y.rem_euclid(h) as usize);
        let i = 4 * (y * t.width as usize + x);
        DVec3::new(
            srgb_to_linear(f64::from(t.rgba[i]) / 255.0),
            srgb_to_linear(f64::from(t.rgba[i + 1]) / 255.0),
            srgb_to_linear(f64::from(t.rgba[i + 2]) / 255.0),
        )
    };
    let st = DVec2::new(uv.x * w as f64 - 0.5, (1.0 - uv.y) * h as f64 - 0.5);
    let base = st.floor();
    let f = st - base;
    let (x, y) = (base.x as i64, base.y as i64);
    let top = texel(x, y).lerp(texel(x + 1, y), f.x);
    let bottom = texel(x, y + 1).lerp(texel(x + 1, y + 1), f.x);
    top.lerp(bottom, f.y)
}
