//! A moving instance over a frame: its placement at knots in time, as `wgsl/triangles.wgsl`
//! interpolates them ([`InstanceKnot`]), and a box that holds its mesh wherever that
//! interpolation puts it in between.

use glam::{DAffine3, DMat3, DQuat, DVec3};

use crate::scene::animation::{Animation, polar};
use crate::shared::InstanceKnot;

/// The most knots a moving instance has in one frame: the window's ends and the keys inside
/// it, each key interval split in [`SPLITS`] where the interpolation is not exact; past this,
/// this many evenly spaced.
pub const MAX_INSTANCE_KNOTS: usize = 32;

/// Pieces a key interval is split into where interpolating the placement between its ends
/// is not the sampler's ([`Animation::piecewise_exact`]: splines, several keyed nodes).
pub const SPLITS: usize = 8;

/// Steps each knot interval's swept box is bounded over.
const BOX_STEPS: usize = 4;

/// A placement between knots, in f64: rotation, the symmetric factor, translation.
#[derive(Clone, Copy)]
struct Polar {
    rotation: DQuat,
    stretch: DMat3,
    translation: DVec3,
}

impl Polar {
    fn between(a: &Polar, b: &Polar, s: f64) -> Polar {
        Polar {
            rotation: a.rotation.slerp(b.rotation, s),
            stretch: a.stretch * (1.0 - s) + b.stretch * s,
            translation: a.translation.lerp(b.translation, s),
        }
    }

    fn affine(&self) -> DAffine3 {
        DAffine3::from_mat3_translation(
            DMat3::from_quat(self.rotation) * self.stretch,
            self.translation,
        )
    }
}

/// A moving instance over a frame.
pub struct Swept {
    /// Its knots in time order (times from the frame's stamp; translations camera-relative).
    pub knots: Vec<InstanceKnot>,
    /// A box (camera-relative) holding its mesh at every time of the window; `None` where a
    /// placement flattens it throughout.
    pub bounds: Option<(DVec3, DVec3)>,
}

/// The knot times in `window` (seconds from the stamp, scene time `stamp + τ`) for
/// `animation`: its ends, the keys inside, and splits where interpolation is not exact.
fn knot_times(animation: &Animation, stamp: f64, (lo, hi): (f64, f64)) -> Vec<f64> {
    let mut times = vec![lo];
    times.extend(
        animation
            .key_times()
            .into_iter()
            .map(|k| k - stamp)
            .filter(|&k| k > lo && k < hi),
    );
    times.push(hi);
    if !animation.piecewise_exact() {
        times = times
            .windows(2)
            .flat_map(|w| (0..SPLITS).map(move |k| w[0] + (w[1] - w[0]) * k as f64 / SPLITS as f64))
            .chain([hi])
            .collect();
    }
    times.dedup();
    if times.len() > MAX_INSTANCE_KNOTS {
        let n = MAX_INSTANCE_KNOTS - 1;
        times = (0..=n)
            .map(|k| lo + (hi - lo) * k as f64 / n as f64)
            .collect();
    }
    times
}

/// `animation` over `window` (seconds from scene time `stamp`), for a mesh whose box is
/// `mesh_box`, relative to `origin`.
pub fn sweep(
    animation: &Animation,
    stamp: f64,
    window: (f64, f64),
    mesh_box: (DVec3, DVec3),
    origin: DVec3,
) -> Swept {
    let times = knot_times(animation, stamp, window);
    let sampled: Vec<DAffine3> = times.iter().map(|&t| animation.at(stamp + t)).collect();
    let decomposed: Vec<Option<Polar>> = sampled
        .iter()
        .map(|m| {
            polar(m.matrix3).map(|(rotation, stretch)| Polar {
                rotation,
                stretch,
                translation: m.translation - origin,
            })
        })
        .collect();
    // A placement that flattens the mesh (a scale keyed to zero) keeps a neighbour's
    // rotation with no extent: the mesh shrinks to it and hides there.
    let fallback = decomposed.iter().flatten().next().copied();
    let mut last = fallback;
    let placements: Vec<Option<Polar>> = sampled
        .iter()
        .zip(&decomposed)
        .map(|(m, d)| {
            if d.is_some() {
                last = *d;
            }
            d.or_else(|| {
                last.map(|l| Polar {
                    rotation: l.rotation,
                    stretch: DMat3::ZERO,
                    translation: m.translation - origin,
                })
            })
        })
        .collect();
    let knots = times
        .iter()
        .zip(&placements)
        .map(|(&t, p)| {
            let p = p.unwrap_or(Polar {
                rotation: DQuat::IDENTITY,
                stretch: DMat3::ZERO,
                translation: DVec3::ZERO,
            });
            let a = p.stretch;
            let q = p.rotation.normalize().as_quat();
            let v = p.translation.as_vec3();
            InstanceKnot {
                rotation: q.to_array(),
                translation: [v.x, v.y, v.z, t as f32],
                diagonal: [a.x_axis.x, a.y_axis.y, a.z_axis.z, a.y_axis.x].map(|x| x as f32),
                off_diagonal: [a.z_axis.x as f32, a.z_axis.y as f32, 0.0, 0.0],
            }
        })
        .collect();
    let bounds = fallback.and_then(|_| swept_box(&placements, mesh_box));
    Swept { knots, bounds }
}

/// A box around the mesh box's corners wherever the interpolation between `placements`
/// puts them. Over a step from a to b, a corner x moves from M(a)x by at most
/// |T(b) - T(a)| + |x| (‖A(b) - A(a)‖_F + θ ‖A(a)‖_F), θ the turn from R(a) to R(b)
/// (a rotation by φ moves a vector y by 2 sin(φ/2)|y| ≤ φ|y|): each step's box at a,
/// padded by that.
fn swept_box(placements: &[Option<Polar>], (lo, hi): (DVec3, DVec3)) -> Option<(DVec3, DVec3)> {
    let reach = lo.abs().max(hi.abs()).length();
    let mut out: Option<(DVec3, DVec3)> = None;
    let mut grow = |p: &Polar, pad: f64| {
        let (a, b) = crate::scene::placed_box((lo, hi), p.affine());
        let (a, b) = (a - DVec3::splat(pad), b + DVec3::splat(pad));
        out = Some(match out {
            Some((x, y)) => (x.min(a), y.max(b)),
            None => (a, b),
        });
    };
    let placements: Vec<Polar> = placements.iter().flatten().copied().collect();
    for w in placements.windows(2) {
        for k in 0..BOX_STEPS {
            let at = |s: f64| Polar::between(&w[0], &w[1], s);
            let (a, b) = (
                at(k as f64 / BOX_STEPS as f64),
                at((k + 1) as f64 / BOX_STEPS as f64),
            );
            let turn = a.rotation.angle_between(b.rotation);
            let frobenius = |m: DMat3| {
                (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared())
                    .sqrt()
            };
            let pad = (b.translation - a.translation).length()
                + reach * (frobenius(b.stretch - a.stretch) + turn * frobenius(a.stretch));
            grow(&a, pad);
        }
    }
    if let Some(last) = placements.last() {
        grow(last, 0.0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::animation::{Factor, Interpolation, Keys, Trs};

    fn turning_and_growing() -> Animation {
        let keys = |times: Vec<f64>| (times, Interpolation::Linear);
        let (times, interpolation) = keys(vec![0.0, 1.0]);
        Animation {
            factors: vec![Factor::Keyed(Trs {
                translation: DVec3::ZERO,
                rotation: DQuat::IDENTITY,
                scale: DVec3::ONE,
                translation_keys: Some(Keys {
                    times: times.clone(),
                    values: vec![DVec3::ZERO, DVec3::new(3.0, 0.0, 0.0)],
                    interpolation,
                }),
                rotation_keys: Some(Keys {
                    times: times.clone(),
                    values: vec![DQuat::IDENTITY, DQuat::from_rotation_z(2.5)],
                    interpolation,
                }),
                scale_keys: Some(Keys {
                    times,
                    values: vec![DVec3::new(1.0, 2.0, 0.5), DVec3::new(2.0, 0.5, 1.0)],
                    interpolation,
                }),
            })],
        }
    }

    /// Between knots, the GPU's interpolation (slerp of the polar rotation, the rest linear)
    /// of one keyed node is the sampler's placement to rounding; every corner of the mesh at
    /// 200 times of the window is inside the swept box; knots sit at the window's ends and
    /// the keys inside.
    #[test]
    fn knots_interpolate_the_sampler_and_the_box_holds_the_sweep() {
        let animation = turning_and_growing();
        let mesh_box = (DVec3::new(-1.0, -0.5, -0.2), DVec3::new(0.5, 1.0, 0.3));
        let origin = DVec3::new(0.1, 0.2, 0.3);
        // Scene time 0.2 + τ for τ in [-0.3, 0.6]: the key at 1.0 is inside, at τ = 0.8 - no,
        // scene 1.0 is τ = 0.8, outside; the key at 0 is τ = -0.2, inside.
        let swept = sweep(&animation, 0.2, (-0.3, 0.6), mesh_box, origin);
        let times: Vec<f32> = swept.knots.iter().map(|k| k.translation[3]).collect();
        assert_eq!(times, vec![-0.3, -0.2, 0.6]);
        let (lo, hi) = swept.bounds.unwrap();
        for k in 0..=200 {
            let tau = -0.3 + 0.9 * f64::from(k) / 200.0;
            let m = animation.at(0.2 + tau);
            // The interpolation as the kernel does it, in f64.
            let j = times
                .partition_point(|&t| f64::from(t) <= tau)
                .clamp(1, times.len() - 1)
                - 1;
            let knot = |i: usize| {
                let k = &swept.knots[i];
                let d = k.diagonal.map(f64::from);
                let o = k.off_diagonal.map(f64::from);
                Polar {
                    rotation: DQuat::from_array(k.rotation.map(f64::from)),
                    stretch: DMat3::from_cols_array(&[
                        d[0], d[3], o[0], d[3], d[1], o[1], o[0], o[1], d[2],
                    ]),
                    translation: DVec3::new(
                        k.translation[0].into(),
                        k.translation[1].into(),
                        k.translation[2].into(),
                    ),
                }
            };
            let (ta, tb) = (f64::from(times[j]), f64::from(times[j + 1]));
            let s = ((tau - ta) / (tb - ta)).clamp(0.0, 1.0);
            let gpu = Polar::between(&knot(j), &knot(j + 1), s).affine();
            let sampler = DAffine3::from_translation(-origin) * m;
            assert!(
                gpu.abs_diff_eq(sampler, 1e-5),
                "τ {tau}: {gpu:?} against {sampler:?}"
            );
            for c in 0..8 {
                let pick = |bit: i32, a: f64, b: f64| if c & bit == 0 { a } else { b };
                let corner = DVec3::new(
                    pick(1, mesh_box.0.x, mesh_box.1.x),
                    pick(2, mesh_box.0.y, mesh_box.1.y),
                    pick(4, mesh_box.0.z, mesh_box.1.z),
                );
                let p = sampler.transform_point3(corner);
                assert!(
                    p.cmpge(lo - 1e-9).all() && p.cmple(hi + 1e-9).all(),
                    "τ {tau}: {p}"
                );
            }
        }
    }

    /// The polar decomposition of a turned, unevenly scaled (and a mirrored) matrix gives back
    /// the rotation and a symmetric factor whose product is the matrix.
    #[test]
    fn polar_factors_multiply_back() {
        let r = DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.2, 2.0);
        for scale in [DVec3::new(2.0, 0.5, 1.5), DVec3::new(-1.0, 3.0, 0.2)] {
            let m = DMat3::from_quat(r) * DMat3::from_diagonal(scale);
            let (q, a) = polar(m).unwrap();
            assert!((DMat3::from_quat(q) * a).abs_diff_eq(m, 1e-12));
            assert!(a.abs_diff_eq(a.transpose(), 1e-12));
            if scale.min_element() > 0.0 {
                assert!(q.abs_diff_eq(r, 1e-12) || q.abs_diff_eq(-r, 1e-12));
            }
        }
        assert!(polar(DMat3::ZERO).is_none());
    }
}
