//! A trajectory made smooth for an IMU ([`Spline`]): a uniform cumulative cubic B-spline on
//! SO(3) × R³ whose control poses are the trajectory sampled at a fixed step (between stamps
//! by slerp, [`super::trajectory::pose_at`]). Kim, Kim and Shin ("A General Construction
//! Scheme for Unit Quaternion Curves with Simple High Order Derivatives", SIGGRAPH 1995) give
//! the cumulative form: with u the share of a segment and the cumulative basis
//! B̃₁ = (5 + 3u - 3u² + u³)/6, B̃₂ = (1 + 3u + 3u² - 2u³)/6, B̃₃ = u³/6,
//! R(u) = R₀ · Π exp(B̃ⱼ φⱼ) with φⱼ = log(Rⱼ₋₁⁻¹ Rⱼ), and p(u) = p₀ + Σ B̃ⱼ (pⱼ - pⱼ₋₁). It is
//! C² (so acceleration and angular rate are continuous) and passes near, not through, its
//! controls. The body's angular rate follows the recursion of Sommer, Usenko, Schubert,
//! Demmel and Cremers ("Efficient Derivative Computation for Cumulative B-Splines on Lie
//! Groups", CVPR 2020): ω₀ = 0, ωⱼ = exp(-B̃ⱼ φⱼ) ωⱼ₋₁ + B̃ⱼ' φⱼ.

use glam::{DAffine3, DQuat, DVec3};

use super::trajectory::{Pose, pose_at};

/// A uniform cumulative cubic B-spline through a trajectory's poses (see the module docs).
#[derive(Clone, Debug)]
pub struct Spline {
    /// The first control's time, seconds.
    start: f64,
    /// Seconds between controls.
    step: f64,
    /// The control poses: rotation (body to world) and position.
    controls: Vec<(DQuat, DVec3)>,
}

/// The spline's state at one time: the pose, the body's angular rate (body frame, rad/s) and
/// the acceleration (world frame, m/s²).
#[derive(Clone, Copy, Debug)]
pub struct Moving {
    /// `T_world_body`.
    pub pose: DAffine3,
    /// Angular rate in the body's frame.
    pub rate: DVec3,
    /// Velocity in the world frame.
    pub velocity: DVec3,
    /// Acceleration in the world frame.
    pub acceleration: DVec3,
}

impl Spline {
    /// The spline whose controls are `trajectory` every `step` seconds from its first stamp;
    /// `None` where it spans fewer than four controls.
    pub fn new(trajectory: &[Pose], step: f64) -> Option<Self> {
        let (first, last) = (trajectory.first()?, trajectory.last()?);
        if step.is_nan() || step <= 0.0 {
            return None;
        }
        let count = ((last.seconds - first.seconds) / step * (1.0 + 1e-12)).floor() as usize + 1;
        if count < 4 {
            return None;
        }
        let mut controls: Vec<(DQuat, DVec3)> = (0..count)
            .map(|k| {
                let t = (first.seconds + k as f64 * step).min(last.seconds);
                let pose = pose_at(trajectory, t).expect("inside the trajectory");
                let q = DQuat::from_mat3(&pose.matrix3).normalize();
                (q, pose.translation)
            })
            .collect();
        // Each rotation on the same side as the one before, so each φ is the short way.
        for k in 1..controls.len() {
            if controls[k].0.dot(controls[k - 1].0) < 0.0 {
                controls[k].0 = -controls[k].0;
            }
        }
        Some(Self {
            start: first.seconds,
            step,
            controls,
        })
    }

    /// Seconds between controls.
    pub fn step(&self) -> f64 {
        self.step
    }

    /// The times the spline is defined between: its second control's to its last but one's.
    pub fn span(&self) -> (f64, f64) {
        let n = self.controls.len() as f64;
        (self.start + self.step, self.start + (n - 2.0) * self.step)
    }

    /// The state at `t` seconds, `None` outside [`Spline::span`].
    pub fn at(&self, t: f64) -> Option<Moving> {
        let (a, b) = self.span();
        if !(a..=b).contains(&t) {
            return None;
        }
        let x = (t - a) / self.step;
        let segment = (x.floor() as usize).min(self.controls.len() - 4);
        let u = x - segment as f64;
        let c = &self.controls[segment..segment + 4];
        let (u2, u3) = (u * u, u * u * u);
        let basis = [
            (5.0 + 3.0 * u - 3.0 * u2 + u3) / 6.0,
            (1.0 + 3.0 * u + 3.0 * u2 - 2.0 * u3) / 6.0,
            u3 / 6.0,
        ];
        let slope = [
            (3.0 - 6.0 * u + 3.0 * u2) / 6.0,
            (3.0 + 6.0 * u - 6.0 * u2) / 6.0,
            3.0 * u2 / 6.0,
        ];
        let curve = [(-6.0 + 6.0 * u) / 6.0, (6.0 - 12.0 * u) / 6.0, u];
        let (mut rotation, mut position) = c[0];
        let (mut velocity, mut acceleration) = (DVec3::ZERO, DVec3::ZERO);
        let mut rate = DVec3::ZERO;
        for j in 1..4 {
            let phi = (c[j - 1].0.inverse() * c[j].0).to_scaled_axis();
            let turn = DQuat::from_scaled_axis(phi * basis[j - 1]);
            rotation *= turn;
            rate = turn.inverse() * rate + phi * slope[j - 1];
            let d = c[j].1 - c[j - 1].1;
            position += d * basis[j - 1];
            velocity += d * slope[j - 1];
            acceleration += d * curve[j - 1];
        }
        Some(Moving {
            pose: DAffine3::from_rotation_translation(rotation.normalize(), position),
            rate: rate / self.step,
            velocity: velocity / self.step,
            acceleration: acceleration / (self.step * self.step),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::trajectory::{TrajectoryFormat, parse};

    /// A body going round a circle of radius 2 at 1 rad/s, facing along its path (a steady
    /// turn about z), sampled every 10 ms: the spline's rate is the turn's (1 rad/s about z)
    /// and its acceleration the centripetal 2 m/s² towards the centre, within the
    /// approximation of a circle by its chords (1e-3); numerically differentiated poses agree
    /// with its rate and velocity (the derivatives are the spline's own), and rate and
    /// acceleration are continuous across segments.
    #[test]
    fn a_steady_turn_has_the_turns_rate_and_centripetal_acceleration() {
        let text: String = (0..=400)
            .map(|k| {
                let t = f64::from(k) * 0.01;
                let (s, c) = (t / 2.0).sin_cos();
                let (x, y) = (2.0 * t.cos(), 2.0 * t.sin());
                format!("{t} {x} {y} 0 0 0 {s} {c}\n")
            })
            .collect();
        let trajectory = parse(&text, TrajectoryFormat::Tum, 1.0).unwrap();
        let spline = Spline::new(&trajectory, 0.05).unwrap();
        let (a, b) = spline.span();
        assert!(
            (a - 0.05).abs() < 1e-12 && (b - 3.95).abs() < 1e-9,
            "{a} {b}"
        );
        let mut t = a;
        while t <= b {
            let m = spline.at(t).unwrap();
            assert!(
                (m.rate - DVec3::Z).length() < 1e-3,
                "t {t}: rate {}",
                m.rate
            );
            let p = m.pose.translation;
            let inward = -DVec3::new(p.x, p.y, 0.0).normalize() * 2.0;
            assert!(
                (m.acceleration - inward).length() < 1e-2,
                "t {t}: {}",
                m.acceleration
            );
            // Central differences of the spline's own poses.
            let h = 1e-5;
            let (before, after) = (spline.at(t - h), spline.at(t + h));
            if let (Some(before), Some(after)) = (before, after) {
                let v = (after.pose.translation - before.pose.translation) / (2.0 * h);
                assert!((v - m.velocity).length() < 1e-6, "t {t}: velocity");
                let r0 = DQuat::from_mat3(&before.pose.matrix3);
                let r1 = DQuat::from_mat3(&after.pose.matrix3);
                let w = (r0.inverse() * r1).to_scaled_axis() / (2.0 * h);
                assert!(
                    (w - m.rate).length() < 1e-5,
                    "t {t}: rate {w} against {}",
                    m.rate
                );
            }
            t += 0.0123;
        }
        assert!(spline.at(a - 1e-9).is_none() && spline.at(b + 1e-9).is_none());
    }
}
