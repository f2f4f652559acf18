//! Camera poses from text, as `fisheye render --camera` and the web page's `camera` give them.

use glam::DVec3;

use super::{Camera, Scene};

impl Scene {
    /// A camera pose from text, as `fisheye render --camera` and the web page's `camera` take it:
    /// `X,Y,Z:LX,LY,LZ` (eye and look-at point, y up), `path:S` for the point S ∈ [0, 1] along
    /// the scene's camera path, or `gltf:N` for its glTF file's camera N (from 0). The error says
    /// which form was expected.
    pub fn parse_camera(&self, text: &str) -> Result<Camera, String> {
        if let Some(s) = text.strip_prefix("path:") {
            let s = s
                .parse()
                .ok()
                .filter(|s: &f64| (0.0..=1.0).contains(s))
                .ok_or_else(|| format!("--camera {text:?}: S must be a number in [0, 1]"))?;
            if self.camera_path.is_empty() {
                return Err(format!("--camera {text:?}: this scene has no camera path"));
            }
            return Ok(self.camera_on_path(s));
        }
        if let Some(n) = text.strip_prefix("gltf:") {
            let n: usize = n
                .parse()
                .map_err(|_| format!("--camera {text:?}: N must be a camera's number, from 0"))?;
            return self.cameras.get(n).copied().ok_or_else(|| {
                format!(
                    "--camera {text:?}: the scene's file has {} camera(s)",
                    self.cameras.len()
                )
            });
        }
        let triple = |t: &str| -> Option<DVec3> {
            let v: Vec<f64> = t
                .split(',')
                .map(|x| x.trim().parse().ok())
                .collect::<Option<_>>()?;
            (v.len() == 3 && v.iter().all(|x| x.is_finite())).then(|| DVec3::new(v[0], v[1], v[2]))
        };
        let (position, look_at) = text
            .split_once(':')
            .and_then(|(p, l)| Some((triple(p)?, triple(l)?)))
            .filter(|(p, l)| p != l)
            .ok_or_else(|| {
                format!(
                    "--camera {text:?}: expected X,Y,Z:LX,LY,LZ (two different finite points), \
                     path:S or gltf:N"
                )
            })?;
        Ok(Camera {
            position,
            look_at,
            up: DVec3::Y,
        })
    }
}
