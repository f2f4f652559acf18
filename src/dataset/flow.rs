//! Ground truth between frames, through the lens: optical flow (where each pixel's primary
//! hit lands in another frame, and whether it is seen there) and scene flow (how the hit
//! moves in the camera's frame), from two frames' range and the cameras' motions, in f64.
//!
//! A pixel's hit is the point its centre ray meets at its line's time (a rolling shutter's
//! lines are read at different times; see [`crate::lens::Shutter`]). It lands in the other
//! frame where the lens projects it from the camera at the time of the line it lands on: with
//! a rolling shutter that time depends on where it lands, so the landing is iterated to a
//! fixed point (the image moving less than a line a line time converges; otherwise there is
//! none). It is seen there (covisible) where the other frame's pixel under it has a hit at the
//! point's distance, within the spread of range across a pixel's footprint on a slanted
//! surface (derived at `covisible`). A hit on a moving instance moves with it: it is where
//! the instance's animation puts the same point of its mesh at each time ([`Movers`]).

use glam::{DAffine3, DVec2, DVec3};

use crate::lens::LensCamera;
use crate::scene::Scene;
use crate::scene::animation::Animation;
use crate::shared::NO_HIT;
use crate::trace::{Motion, RenderOutput};

/// A scene's moving instances, by the scene triangles (ids) they hold.
pub struct Movers<'a> {
    scene: &'a Scene,
    /// Each instance's first scene triangle id ([`Scene::instance_starts`]).
    starts: Vec<u64>,
}

impl<'a> Movers<'a> {
    /// `scene`'s moving instances; `None` where nothing moves.
    pub fn new(scene: &'a Scene) -> Option<Self> {
        scene.moves().then(|| Movers {
            scene,
            starts: scene.instance_starts(),
        })
    }

    /// The animation moving scene triangle `id`, if it moves.
    fn animation(&self, id: u32) -> Option<&'a Animation> {
        let id = u64::from(id);
        let k = self.starts.partition_point(|&s| s <= id).checked_sub(1)?;
        let instance = &self.scene.instances[k];
        let animation = instance.animation?;
        let inside = id < self.starts[k] + u64::from(instance.count);
        inside.then(|| &self.scene.animations[animation as usize])
    }
}

/// A hit point over time: still, or a point of a moving instance's mesh.
enum Tracked<'a> {
    Still(DVec3),
    Moving(DVec3, &'a Animation),
}

impl Tracked<'_> {
    /// Where it is at scene time `t`.
    fn at(&self, t: f64) -> DVec3 {
        match self {
            Tracked::Still(p) => *p,
            Tracked::Moving(local, animation) => animation.at(t).transform_point3(*local),
        }
    }
}

/// One camera's frame as flow reads it.
pub struct Seen<'a> {
    /// The camera: lens, image size and shutter.
    pub camera: &'a LensCamera,
    /// Its motion over the frame ([`Motion::still`] for a still one).
    pub motion: &'a Motion,
    /// The frame's outputs: range, normal and id of each pixel's centre ray.
    pub output: &'a RenderOutput,
    /// The camera-frame direction of each pixel's centre ([`LensCamera::directions`]).
    pub directions: &'a [Option<DVec3>],
    /// The scene time of the frame's stamp.
    pub time: f64,
    /// The scene's moving instances, if any.
    pub movers: Option<&'a Movers<'a>>,
}

/// Rolling-shutter landings iterated at most this often.
const LANDING_STEPS: usize = 50;

impl Seen<'_> {
    /// Pixel `i`'s centre in `camera`'s image.
    fn centre_of(camera: &LensCamera, i: usize) -> DVec2 {
        let w = camera.size.width as usize;
        DVec2::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5)
    }

    /// Pixel `i`'s centre.
    fn centre(&self, i: usize) -> DVec2 {
        Self::centre_of(self.camera, i)
    }

    /// `T_scene_camera` at pixel `i`'s line time.
    fn pose(&self, i: usize) -> DAffine3 {
        let t = self.camera.time_at(self.centre(i));
        self.motion.camera_at(t)
    }

    /// Pixel `i`'s primary hit (moving with its instance where that moves), where it was
    /// then, and the camera's pose it was seen from; `None` where it has no hit (a miss or a
    /// masked pixel).
    fn hit(&self, i: usize) -> Option<(Tracked<'_>, DVec3, DAffine3)> {
        let d = self.directions[i]?;
        let id = self.output.ids[i];
        if id == NO_HIT {
            return None;
        }
        let pose = self.pose(i);
        let range = f64::from(self.output.geometry[i][3]);
        let point = pose.transform_point3(d * range);
        let tracked = match self.movers.and_then(|m| m.animation(id)) {
            Some(animation) => {
                let t = self.time + self.camera.time_at(self.centre(i));
                let local = animation.at(t).inverse().transform_point3(point);
                Tracked::Moving(local, animation)
            }
            None => Tracked::Still(point),
        };
        Some((tracked, point, pose))
    }

    /// Where `point` lands in this frame's image (a continuous position), the camera's pose
    /// at that position's time and the point then; `None` where the lens does not see it, it
    /// falls outside the image, or a rolling shutter's landing has no fixed point.
    fn land(&self, point: &Tracked) -> Option<(DVec2, DAffine3, DVec3)> {
        let camera = self.camera;
        // The camera and the point at `t` seconds from the stamp, and where the lens sees it.
        let at = |t: f64| {
            let (pose, p) = (self.motion.camera_at(t), point.at(self.time + t));
            (camera.project(pose.inverse().transform_point3(p)), pose, p)
        };
        let (pixel, mut pose, mut p) = at(0.0);
        let mut pixel = pixel?;
        if camera.shutter.line_delay == 0.0 {
            return Some((pixel, pose, p));
        }
        for _ in 0..LANDING_STEPS {
            let (next, next_pose, next_p) = at(camera.time_at(pixel));
            let next = next?;
            (pose, p) = (next_pose, next_p);
            let moved = (next - pixel).length();
            pixel = next;
            if moved < 1e-9 {
                return Some((pixel, pose, p));
            }
        }
        None
    }

    /// The pixel with a ray nearest a continuous position, among the four whose centres
    /// surround it (at the lens's edge the one under it may have none).
    fn nearest(&self, p: DVec2) -> Option<usize> {
        let (w, h) = (
            self.camera.size.width as i64,
            self.camera.size.height as i64,
        );
        let corner = (p - 0.5).floor();
        let (x0, y0) = (corner.x as i64, corner.y as i64);
        let mut around: Vec<(f64, usize)> = [(0, 0), (1, 0), (0, 1), (1, 1)]
            .into_iter()
            .map(|(dx, dy)| (x0 + dx, y0 + dy))
            .filter(|&(x, y)| (0..w).contains(&x) && (0..h).contains(&y))
            .map(|(x, y)| {
                let i = (y * w + x) as usize;
                ((self.centre(i) - p).length_squared(), i)
            })
            .filter(|&(_, i)| self.directions[i].is_some())
            .collect();
        around.sort_by(|a, b| a.0.total_cmp(&b.0));
        around.first().map(|&(_, i)| i)
    }
}

/// Whether `point`, landing nearest pixel `q` of `seen` (the nearest with a ray) from the
/// camera at `pose`, is what that pixel sees. Its distance δ from the camera must be the
/// pixel's range r within r·(10⁻³ + 0.75·α·tan β): the landing lies about √2/2 px from the
/// pixel's centre, where a
/// surface at angle β to the ray (from the pixel's normal) is r·α·tan β farther or nearer per
/// pixel of angle α; 10⁻³ covers the ranges' f32 and the lines' times rounding (tan β is
/// held to 50, grazing). A pixel that sees nothing, or something nearer or farther, does not
/// see the point (occluded, or beside an edge).
fn covisible(seen: &Seen, q: Option<usize>, point: DVec3, pose: &DAffine3) -> bool {
    let Some((q, d)) = q.and_then(|q| Some((q, seen.directions[q]?))) else {
        return false;
    };
    if seen.output.ids[q] == NO_HIT {
        return false;
    }
    let g = seen.output.geometry[q];
    let (range, normal) = (
        f64::from(g[3]),
        DVec3::new(g[0].into(), g[1].into(), g[2].into()),
    );
    let ray = point - pose.translation;
    let distance = ray.length();
    // The normal is f32: |cos| may round past 1.
    let cos = (normal.dot(ray) / distance)
        .abs()
        .clamp(1.0 / 50f64.hypot(1.0), 1.0);
    let tan = (1.0 - cos * cos).sqrt() / cos;
    // The pixel's angular size: the angle to a neighbour's centre ray.
    let w = seen.camera.size.width as usize;
    let neighbour = [q + 1, q.wrapping_sub(1)]
        .into_iter()
        .filter(|&n| n < seen.directions.len() && n / w == q / w)
        .find_map(|n| seen.directions[n]);
    let alpha = neighbour.map_or(0.01, |n| n.angle_between(d));
    (distance - range).abs() <= range * (1e-3 + 0.75 * alpha * tan)
}

/// Optical flow from one frame to another, row-major: each pixel's vector from its centre to
/// where its hit lands in `to` (pixels; x right, y down), NaN where it has no hit or does
/// not land (or there is no `to`); and 1 where `to` sees the hit there (the module docs say how).
pub fn optical_flow(from: &Seen, to: Option<&Seen>) -> (Vec<[f32; 2]>, Vec<u8>) {
    (0..from.directions.len())
        .map(|i| {
            let landed = to.and_then(|to| {
                let (point, _, _) = from.hit(i)?;
                let (pixel, pose, point) = to.land(&point)?;
                let seen = covisible(to, to.nearest(pixel), point, &pose);
                Some((pixel - from.centre(i), seen))
            });
            match landed {
                Some((v, seen)) => ([v.x as f32, v.y as f32], u8::from(seen)),
                None => ([f32::NAN; 2], 0),
            }
        })
        .unzip()
}

/// Scene flow from one frame to another, row-major: how each pixel's hit moves in the
/// camera's frame (metres, OpenCV axes), from where `from` saw it to where `to`'s camera is
/// at the time it lands there (its stamp where it does not land); NaN where the pixel has no
/// hit (or there is no `to`).
pub fn scene_flow(from: &Seen, to: Option<&Seen>) -> Vec<[f32; 3]> {
    (0..from.directions.len())
        .map(|i| {
            let moved = to.and_then(|to| {
                let (tracked, point, pose) = from.hit(i)?;
                let (after, moved) = to.land(&tracked).map_or_else(
                    || (to.motion.camera_at(0.0), tracked.at(to.time)),
                    |(_, pose, p)| (pose, p),
                );
                let before = pose.inverse().transform_point3(point);
                Some(after.inverse().transform_point3(moved) - before)
            });
            moved.map_or([f32::NAN; 3], |v| v.as_vec3().to_array())
        })
        .collect()
}

pub mod files;
#[cfg(test)]
mod tests;
