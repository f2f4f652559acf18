//! Moving instances: where a placed mesh is at each scene time ([`Animation`]), as glTF's
//! animation samplers define it (glTF 2.0 specification, §3.11 "Animations" and Appendix C
//! "Interpolation"): translation, rotation and scale channels of a node, each keyed in time with
//! step, linear (rotations by slerp) or cubic Hermite spline interpolation, held at the first
//! and last keys outside them; a node's transform is translation · rotation · scale, and a mesh's
//! placement is the product of its node's and its ancestors' (root first). Scene files key
//! their instances the same way (linear).

use glam::{DAffine3, DMat3, DQuat, DVec3};

/// How a channel goes from one key to the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The earlier key's value until the next key.
    Step,
    /// Linear (spherical linear for rotations).
    Linear,
    /// Cubic Hermite spline through the keys, with in- and out-tangents given per key;
    /// rotations are normalised after.
    CubicSpline,
}

/// One property's keys: `times` strictly increasing (seconds of scene time); `values` one
/// per key, or for [`Interpolation::CubicSpline`] three (in-tangent, value, out-tangent).
#[derive(Clone, Debug, PartialEq)]
pub struct Keys<T> {
    /// Key times, strictly increasing.
    pub times: Vec<f64>,
    /// The values (see above).
    pub values: Vec<T>,
    /// Between keys.
    pub interpolation: Interpolation,
}

/// What a channel's values can do between keys.
pub trait Keyed: Copy {
    /// Linear interpolation from `a` to `b` at `s` (rotations: slerp on the shortest arc).
    fn between(a: Self, b: Self, s: f64) -> Self;
    /// `Σ wᵢ vᵢ`, for the Hermite basis (rotations normalised after).
    fn combine(terms: [(f64, Self); 4]) -> Self;
    /// Whether every component is finite.
    fn finite(&self) -> bool;
}

impl Keyed for DVec3 {
    fn between(a: Self, b: Self, s: f64) -> Self {
        a.lerp(b, s)
    }

    fn combine(terms: [(f64, Self); 4]) -> Self {
        terms.iter().map(|&(w, v)| w * v).sum()
    }

    fn finite(&self) -> bool {
        self.is_finite()
    }
}

impl Keyed for DQuat {
    fn between(a: Self, b: Self, s: f64) -> Self {
        // glam's slerp takes the shorter arc, as glTF's reference implementation does.
        a.slerp(b, s)
    }

    fn combine(terms: [(f64, Self); 4]) -> Self {
        let v: glam::DVec4 = terms.iter().map(|&(w, q)| w * glam::DVec4::from(q)).sum();
        DQuat::from_vec4(v).normalize()
    }

    fn finite(&self) -> bool {
        self.is_finite()
    }
}

impl<T: Keyed> Keys<T> {
    /// How many values each key has.
    fn stride(&self) -> usize {
        match self.interpolation {
            Interpolation::CubicSpline => 3,
            _ => 1,
        }
    }

    /// The key's value (for a spline, the middle of its three).
    fn value(&self, key: usize) -> T {
        self.values[key * self.stride() + self.stride() / 2]
    }

    /// Checks the keys: at least one, times finite and strictly increasing, as many values as
    /// the interpolation needs. The message names what is wrong.
    pub fn check(&self) -> Result<(), String> {
        if self.times.is_empty() {
            return Err("no keys".into());
        }
        if let Some(t) = self.times.iter().find(|t| !t.is_finite()) {
            return Err(format!("key time {t} is not finite"));
        }
        if let Some(k) = (1..self.times.len()).find(|&k| self.times[k] <= self.times[k - 1]) {
            return Err(format!(
                "key times must increase: key {k} at {} s follows {} s",
                self.times[k],
                self.times[k - 1]
            ));
        }
        if let Some(k) = self.values.iter().position(|v| !v.finite()) {
            return Err(format!("value {k} is not finite"));
        }
        let wanted = self.times.len() * self.stride();
        if self.values.len() != wanted {
            return Err(format!(
                "{} keys need {wanted} values ({:?}), and there are {}",
                self.times.len(),
                self.interpolation,
                self.values.len()
            ));
        }
        Ok(())
    }

    /// The value at `t`: the first key's before it, the last's after it.
    pub fn at(&self, t: f64) -> T {
        let times = &self.times;
        let last = times.len() - 1;
        if t <= times[0] {
            return self.value(0);
        }
        if t >= times[last] {
            return self.value(last);
        }
        // The key at or before t.
        let k = times.partition_point(|&k| k <= t) - 1;
        let dt = times[k + 1] - times[k];
        let s = (t - times[k]) / dt;
        match self.interpolation {
            Interpolation::Step => self.value(k),
            Interpolation::Linear => T::between(self.value(k), self.value(k + 1), s),
            Interpolation::CubicSpline => {
                // Appendix C: p(s) = (2s³ - 3s² + 1) v_k + dt (s³ - 2s² + s) b_k
                //                  + (-2s³ + 3s²) v_k+1 + dt (s³ - s²) a_k+1.
                let (s2, s3) = (s * s, s * s * s);
                let out_tangent = self.values[3 * k + 2];
                let in_tangent = self.values[3 * (k + 1)];
                T::combine([
                    (2.0 * s3 - 3.0 * s2 + 1.0, self.value(k)),
                    (dt * (s3 - 2.0 * s2 + s), out_tangent),
                    (-2.0 * s3 + 3.0 * s2, self.value(k + 1)),
                    (dt * (s3 - s2), in_tangent),
                ])
            }
        }
    }
}

/// A node whose translation, rotation and scale may be keyed: unkeyed ones keep the node's.
#[derive(Clone, Debug, PartialEq)]
pub struct Trs {
    /// The node's own translation, rotation and scale.
    pub translation: DVec3,
    /// Its rotation.
    pub rotation: DQuat,
    /// Its scale.
    pub scale: DVec3,
    /// Keys of its translation, if animated.
    pub translation_keys: Option<Keys<DVec3>>,
    /// Keys of its rotation.
    pub rotation_keys: Option<Keys<DQuat>>,
    /// Keys of its scale.
    pub scale_keys: Option<Keys<DVec3>>,
}

impl Trs {
    /// The node's transform at `t`.
    pub fn at(&self, t: f64) -> DAffine3 {
        let translation = self
            .translation_keys
            .as_ref()
            .map_or(self.translation, |k| k.at(t));
        let rotation = self
            .rotation_keys
            .as_ref()
            .map_or(self.rotation, |k| k.at(t));
        let scale = self.scale_keys.as_ref().map_or(self.scale, |k| k.at(t));
        DAffine3::from_scale_rotation_translation(scale, rotation.normalize(), translation)
    }

    fn times(&self) -> impl Iterator<Item = f64> + '_ {
        let t = self.translation_keys.iter().flat_map(|k| k.times.iter());
        let r = self.rotation_keys.iter().flat_map(|k| k.times.iter());
        let s = self.scale_keys.iter().flat_map(|k| k.times.iter());
        t.chain(r).chain(s).copied()
    }

    fn splined(&self) -> bool {
        let cubic = |i: Option<Interpolation>| i == Some(Interpolation::CubicSpline);
        cubic(self.translation_keys.as_ref().map(|k| k.interpolation))
            || cubic(self.rotation_keys.as_ref().map(|k| k.interpolation))
            || cubic(self.scale_keys.as_ref().map(|k| k.interpolation))
    }
}

/// One factor of a placement: a fixed transform, or a keyed node.
#[derive(Clone, Debug, PartialEq)]
pub enum Factor {
    /// A transform that does not move.
    Fixed(DAffine3),
    /// A node with keys.
    Keyed(Trs),
}

/// A mesh's placement in time: the product of its factors (the root's first).
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// The factors, outermost first.
    pub factors: Vec<Factor>,
}

impl Animation {
    /// Mesh space to world at scene time `t` (seconds).
    pub fn at(&self, t: f64) -> DAffine3 {
        self.factors
            .iter()
            .fold(DAffine3::IDENTITY, |acc, f| match f {
                Factor::Fixed(m) => acc * *m,
                Factor::Keyed(trs) => acc * trs.at(t),
            })
    }

    /// Every key time of every channel, sorted, each once.
    pub fn key_times(&self) -> Vec<f64> {
        let mut times: Vec<f64> = self
            .factors
            .iter()
            .flat_map(|f| match f {
                Factor::Fixed(_) => None,
                Factor::Keyed(trs) => Some(trs.times()),
            })
            .flatten()
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }

    /// Whether interpolating the placement between consecutive key times as the GPU does
    /// (its polar decomposition's rotation by slerp, the rest and the translation linearly:
    /// [`polar`]) gives the sampler's placement exactly: one keyed node without splines, the
    /// factors above it similarities (rotation, uniform scale, translation) and none below.
    /// glTF's linear channels move such a node's translation, rotation and scale that way.
    pub fn piecewise_exact(&self) -> bool {
        let keyed: Vec<usize> = (0..self.factors.len())
            .filter(|&i| matches!(self.factors[i], Factor::Keyed(_)))
            .collect();
        let [k] = keyed[..] else {
            return false;
        };
        let Factor::Keyed(trs) = &self.factors[k] else {
            return false;
        };
        k + 1 == self.factors.len()
            && !trs.splined()
            && self.factors[..k].iter().all(|f| match f {
                Factor::Fixed(m) => is_similarity(m.matrix3),
                Factor::Keyed(_) => false,
            })
    }
}

/// Whether `m` is a rotation times a positive uniform scale (to 1e-12 relative).
fn is_similarity(m: DMat3) -> bool {
    let g = m.transpose() * m;
    let s = g.x_axis.x;
    m.determinant() > 0.0 && g.abs_diff_eq(DMat3::from_diagonal(DVec3::splat(s)), 1e-12 * s)
}

/// The polar decomposition `m = R · A` (`R` a rotation, `A` symmetric), by Higham's Newton
/// iteration `Q ← (Q + Q⁻ᵀ) / 2` (Higham 1986, "Computing the polar decomposition — with
/// applications"), which converges quadratically to the orthogonal factor; where `m` mirrors
/// (negative determinant) the rotation is that factor negated and `A` negative definite.
/// `None` where `m` is singular or not finite.
pub fn polar(m: DMat3) -> Option<(DQuat, DMat3)> {
    let det = m.determinant();
    if !(det.is_normal() && m.is_finite()) {
        return None;
    }
    let mut q = m;
    for _ in 0..60 {
        let next = 0.5 * (q + q.inverse().transpose());
        let done = next.abs_diff_eq(q, 1e-15 * q.x_axis.length().max(1.0));
        q = next;
        if done {
            break;
        }
    }
    if det < 0.0 {
        q = -q;
    }
    let a = q.transpose() * m;
    let symmetric = 0.5 * (a + a.transpose());
    Some((DQuat::from_mat3(&q).normalize(), symmetric))
}
