//! Lens prescriptions: real lenses as the glass surfaces a designer lists, traced ray by ray in
//! f64 (sequential ray tracing: each surface once, front to back), with their paraxial
//! quantities from ray-transfer matrices and the mapping of a direction at infinity to the
//! film by its chief ray (the ray through the centre of the aperture stop).
//!
//! The file format is pbrt's (`RealisticCamera`, after Kolb, Mitchell and Hanrahan, "A
//! Realistic Camera Model for Computer Graphics", SIGGRAPH 1995), so published prescriptions
//! load as they are: a row per surface from the front element to the rear, `radius thickness
//! index aperture` in millimetres (radius of curvature, positive when its centre lies behind
//! the surface toward the film; axial distance to the next surface; refractive index of the
//! medium behind the surface, 0 or 1 for air; clear aperture diameter); a radius of 0 is the
//! aperture stop; `#` starts a comment. A fifth column, optional, gives the medium's Abbe
//! number V_d, which makes its index depend on the wavelength ([`Prescription::at_wavelength`]).
//!
//! Coordinates: millimetres, z along the optical axis from the front vertex (z = 0) toward
//! the film, light travelling toward +z.

use std::path::Path;

use std::f64::consts::FRAC_PI_2;

use glam::DVec3;

use crate::error::LensError;

/// The most surfaces a prescription may list.
pub const MAX_SURFACES: usize = 64;

/// The Fraunhofer lines that define a glass's index and Abbe number, nm: C (red, hydrogen),
/// d (yellow, helium) and F (blue, hydrogen). The renderer's red, green and blue channels are
/// traced at C, d and F.
pub const LINE_C_NM: f64 = 656.27;
/// The d line, nm (see [`LINE_C_NM`]).
pub const LINE_D_NM: f64 = 587.56;
/// The F line, nm (see [`LINE_C_NM`]).
pub const LINE_F_NM: f64 = 486.13;

/// One surface of a prescription.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Radius of curvature, mm: positive when its centre lies behind the vertex (toward the
    /// film); 0 for the aperture stop, which is flat.
    pub radius: f64,
    /// Axial distance to the next surface's vertex, mm (the last surface's is unused: the
    /// film's place comes from the focus).
    pub thickness: f64,
    /// Refractive index of the medium behind the surface (1 for air).
    pub index: f64,
    /// Clear aperture diameter, mm.
    pub aperture: f64,
    /// The Abbe number V_d of the medium behind the surface, if the file gives one: its
    /// dispersion (none without).
    pub abbe: Option<f64>,
}

impl Surface {
    /// Whether this is the aperture stop.
    pub fn is_stop(&self) -> bool {
        self.radius == 0.0
    }
}

/// A ray in the lens's frame: a point and a unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// A point on the ray, mm.
    pub origin: DVec3,
    /// Unit direction, toward +z through the lens.
    pub direction: DVec3,
}

/// Why a ray does not get through a surface (its index in the prescription).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blocked {
    /// It misses the surface's sphere, or meets it going backward.
    Missed(usize),
    /// It lands outside the clear aperture.
    Aperture(usize),
    /// Total internal reflection.
    Reflected(usize),
}

/// A 2 × 2 ray-transfer matrix acting on (height, index × slope): paraxial optics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Abcd {
    /// Height from height.
    pub a: f64,
    /// Height from reduced slope.
    pub b: f64,
    /// Reduced slope from height (minus the power).
    pub c: f64,
    /// Reduced slope from reduced slope.
    pub d: f64,
}

impl Abcd {
    const IDENTITY: Abcd = Abcd {
        a: 1.0,
        b: 0.0,
        c: 0.0,
        d: 1.0,
    };

    /// `self` after `first` (the matrix of going through `first`, then `self`).
    fn after(self, first: Abcd) -> Abcd {
        Abcd {
            a: self.a * first.a + self.b * first.c,
            b: self.a * first.b + self.b * first.d,
            c: self.c * first.a + self.d * first.c,
            d: self.c * first.b + self.d * first.d,
        }
    }

    fn refraction(power: f64) -> Abcd {
        Abcd {
            c: -power,
            ..Abcd::IDENTITY
        }
    }

    fn translation(distance: f64, index: f64) -> Abcd {
        Abcd {
            b: distance / index,
            ..Abcd::IDENTITY
        }
    }
}

/// A lens prescription: its surfaces, front to back.
#[derive(Clone, Debug, PartialEq)]
pub struct Prescription {
    surfaces: Vec<Surface>,
    /// Each surface's vertex on the axis, mm from the front vertex.
    vertices: Vec<f64>,
    stop: usize,
}

/// The index of the medium a row's index column names: 0 is air.
fn medium(index: f64) -> f64 {
    if index == 0.0 { 1.0 } else { index }
}

impl Prescription {
    /// Reads a prescription in pbrt's table format from `text` (read from `path`, which
    /// errors name with the line).
    pub fn parse(text: &str, path: &str) -> Result<Self, LensError> {
        let bad = |line: usize, reason: String| LensError::Prescription {
            path: path.to_string(),
            line,
            reason,
        };
        let mut surfaces = Vec::new();
        let mut last_line = 0;
        for (k, line) in text.lines().enumerate() {
            let number = k + 1;
            let data = line.split('#').next().unwrap_or("").trim();
            if data.is_empty() {
                continue;
            }
            let values: Vec<f64> = data
                .split_whitespace()
                .map(|v| v.parse::<f64>().map_err(|_| v))
                .collect::<Result<_, _>>()
                .map_err(|v| bad(number, format!("{v:?} is not a number")))?;
            let (radius, thickness, index, aperture, abbe) = match values[..] {
                [r, t, n, a] => (r, t, n, a, None),
                [r, t, n, a, v] => (r, t, n, a, Some(v)),
                _ => {
                    return Err(bad(
                        number,
                        format!(
                            "{} values; a surface is 4: radius thickness index aperture (mm), \
                             and optionally the Abbe number",
                            values.len()
                        ),
                    ));
                }
            };
            if values.iter().any(|v| !v.is_finite()) {
                return Err(bad(number, "values must be finite".into()));
            }
            if thickness < 0.0 {
                return Err(bad(number, format!("thickness {thickness} mm is negative")));
            }
            if aperture <= 0.0 {
                return Err(bad(
                    number,
                    format!("aperture {aperture} mm: give a diameter above 0"),
                ));
            }
            if index != 0.0 && index < 1.0 {
                return Err(bad(
                    number,
                    format!("index {index}: a refractive index is 1 or more (0 or 1 for air)"),
                ));
            }
            if radius != 0.0 && radius.abs() < aperture / 2.0 {
                return Err(bad(
                    number,
                    format!(
                        "radius {radius} mm is smaller than half the aperture {aperture} mm: \
                         the surface is not a cap of its sphere"
                    ),
                ));
            }
            if let Some(v) = abbe
                && (medium(index) == 1.0 || v <= 0.0)
            {
                return Err(bad(
                    number,
                    format!(
                        "Abbe number {v}: give one above 0, and only for glass (an index above \
                         1)"
                    ),
                ));
            }
            if surfaces.len() == MAX_SURFACES {
                return Err(bad(number, format!("more than {MAX_SURFACES} surfaces")));
            }
            surfaces.push(Surface {
                radius,
                thickness,
                index: medium(index),
                aperture,
                abbe,
            });
            last_line = number;
        }
        let stops: Vec<usize> = (0..surfaces.len())
            .filter(|&k| surfaces[k].is_stop())
            .collect();
        let stop = match stops[..] {
            [stop] => stop,
            [] => {
                return Err(bad(
                    last_line,
                    "no aperture stop (a surface of radius 0)".into(),
                ));
            }
            _ => {
                return Err(bad(
                    last_line,
                    format!("{} aperture stops (radius 0); a lens has one", stops.len()),
                ));
            }
        };
        if surfaces.iter().all(Surface::is_stop) {
            return Err(bad(last_line, "no refracting surface".into()));
        }
        if surfaces[stop].index != 1.0 || stop > 0 && surfaces[stop - 1].index != 1.0 {
            return Err(bad(
                last_line,
                "the aperture stop must sit in air (index 0 or 1 on either side)".into(),
            ));
        }
        if surfaces.last().is_some_and(|s| s.index != 1.0) {
            return Err(bad(
                last_line,
                "the last surface must face the film through air (index 0 or 1)".into(),
            ));
        }
        let mut vertices = Vec::with_capacity(surfaces.len());
        let mut z = 0.0;
        for s in &surfaces {
            vertices.push(z);
            z += s.thickness;
        }
        Ok(Self {
            surfaces,
            vertices,
            stop,
        })
    }

    /// Reads the prescription in the file at `path`.
    pub fn load(path: &Path) -> Result<Self, LensError> {
        let name = path.display().to_string();
        let failed = |reason: String| LensError::Prescription {
            path: name.clone(),
            line: 0,
            reason,
        };
        let bytes = crate::input::read(path, crate::input::InputKind::Prescription)
            .map_err(|e| failed(e.to_string()))?;
        let text = String::from_utf8(bytes).map_err(|_| failed("not UTF-8 text".into()))?;
        Self::parse(&text, &name)
    }

    /// The surfaces, front to back.
    pub fn surfaces(&self) -> &[Surface] {
        &self.surfaces
    }

    /// The aperture stop's index among the surfaces.
    pub fn stop(&self) -> usize {
        self.stop
    }

    /// The axial position of surface `k`'s vertex, mm from the front vertex.
    pub fn vertex(&self, k: usize) -> f64 {
        self.vertices[k]
    }

    /// The rear vertex's axial position, mm from the front vertex.
    pub fn rear_vertex(&self) -> f64 {
        *self.vertices.last().expect("a prescription has surfaces")
    }

    /// Whether any medium's index depends on the wavelength (the file gives Abbe numbers).
    pub fn is_dispersive(&self) -> bool {
        self.surfaces.iter().any(|s| s.abbe.is_some())
    }

    /// The same lens at wavelength `nm`: each medium with an Abbe number V_d takes the index
    /// of Cauchy's two-term law n(λ) = A + B/λ² through its n_d at the d line with
    /// n_F − n_C = (n_d − 1)/V_d (the Abbe number's definition); others keep theirs.
    pub fn at_wavelength(&self, nm: f64) -> Self {
        let mut out = self.clone();
        for s in &mut out.surfaces {
            if let Some(v) = s.abbe {
                let b = (s.index - 1.0) / v / (LINE_F_NM.powi(-2) - LINE_C_NM.powi(-2));
                let a = s.index - b / (LINE_D_NM * LINE_D_NM);
                s.index = a + b / (nm * nm);
            }
        }
        out
    }

    /// The same lens with the stop's diameter scaled by `scale` (stopping down below 1).
    pub fn with_stop_scaled(&self, scale: f64) -> Self {
        let mut out = self.clone();
        out.surfaces[out.stop].aperture *= scale;
        out
    }

    /// Traces `ray` (in the lens frame, before surface `from`) through surfaces `from` to
    /// `to` (exclusive): where it leaves the last, or why it does not; apertures clip it where
    /// `clip` says.
    pub fn trace_range(
        &self,
        ray: Ray,
        from: usize,
        to: usize,
        clip: bool,
    ) -> Result<Ray, Blocked> {
        let mut ray = ray;
        let mut index = if from == 0 {
            1.0
        } else {
            self.surfaces[from - 1].index
        };
        for k in from..to {
            let s = self.surfaces[k];
            let vertex = DVec3::new(0.0, 0.0, self.vertices[k]);
            // In the surface's vertex frame: a nearly flat surface of radius 1e5 mm keeps its
            // precision there, where a sphere centred 1e5 mm away would lose it.
            let local = ray.origin - vertex;
            let (t, normal) =
                intersect(local, ray.direction, s.radius).ok_or(Blocked::Missed(k))?;
            let hit = local + t * ray.direction;
            if clip && hit.x * hit.x + hit.y * hit.y > 0.25 * s.aperture * s.aperture {
                return Err(Blocked::Aperture(k));
            }
            let direction = if s.is_stop() {
                ray.direction
            } else {
                refract(ray.direction, normal, index / s.index).ok_or(Blocked::Reflected(k))?
            };
            ray = Ray {
                origin: hit + vertex,
                direction,
            };
            index = s.index;
        }
        Ok(ray)
    }

    /// Traces `ray` from in front of the lens through every surface, apertures clipping it.
    pub fn trace(&self, ray: Ray) -> Result<Ray, Blocked> {
        self.trace_range(ray, 0, self.surfaces.len(), true)
    }

    /// Traces `ray` from behind the lens (the film's side, travelling toward −z) back out
    /// through every surface, rear to front, apertures clipping it: where it leaves the front
    /// surface, toward the scene. Light runs the same path the other way (the `wgsl/glass.wgsl`
    /// twin traces the rays of film pixels so).
    pub fn trace_from_film(&self, ray: Ray) -> Result<Ray, Blocked> {
        let mut ray = ray;
        for (k, s) in self.surfaces.iter().enumerate().rev() {
            let vertex = DVec3::new(0.0, 0.0, self.vertices[k]);
            // Mirrored in z, the ray travels toward +z onto a surface of the opposite radius.
            let flip = DVec3::new(1.0, 1.0, -1.0);
            let local = (ray.origin - vertex) * flip;
            let (t, normal) =
                intersect(local, ray.direction * flip, -s.radius).ok_or(Blocked::Missed(k))?;
            let hit = (local + t * ray.direction * flip) * flip;
            if hit.x * hit.x + hit.y * hit.y > 0.25 * s.aperture * s.aperture {
                return Err(Blocked::Aperture(k));
            }
            let direction = if s.is_stop() {
                ray.direction
            } else {
                let before = if k == 0 {
                    1.0
                } else {
                    self.surfaces[k - 1].index
                };
                refract(ray.direction, normal * flip, s.index / before)
                    .ok_or(Blocked::Reflected(k))?
            };
            ray = Ray {
                origin: hit + vertex,
                direction,
            };
        }
        Ok(ray)
    }

    /// The paraxial ray-transfer matrix from the front vertex's plane to surface `to`'s
    /// vertex plane, refracting at every surface before `to` (through all of them for `to` =
    /// the number of surfaces, ending at the rear vertex).
    pub fn abcd(&self, to: usize) -> Abcd {
        let mut m = Abcd::IDENTITY;
        let mut index = 1.0;
        for (k, s) in self.surfaces.iter().enumerate().take(to) {
            if !s.is_stop() {
                m = Abcd::refraction((s.index - index) / s.radius).after(m);
            }
            index = s.index;
            if k + 1 < self.surfaces.len() {
                m = Abcd::translation(s.thickness, index).after(m);
            }
        }
        m
    }

    /// Effective focal length, mm (paraxial; rear, into air).
    pub fn efl(&self) -> f64 {
        -1.0 / self.abcd(self.surfaces.len()).c
    }

    /// Back focal length: from the rear vertex to the paraxial focus of light from infinity,
    /// mm.
    pub fn bfl(&self) -> f64 {
        let m = self.abcd(self.surfaces.len());
        -m.a / m.c
    }

    /// Where the film goes to focus an axial point `distance` mm in front of the front vertex:
    /// its distance behind the rear vertex, mm (paraxial: the image of the point through the
    /// ray-transfer matrix); `None` where the image is virtual (the point is too close).
    pub fn focus_distance(&self, distance: f64) -> Option<f64> {
        let m = self.abcd(self.surfaces.len());
        // A ray from the axis point with slope u reaches the front plane at height d·u, and
        // leaves at height (a d + b) u with reduced slope (c d + d') u: it meets the axis
        // again -(a d + b) / (c d + d') behind the rear vertex.
        let (y, u) = (m.a * distance + m.b, m.c * distance + m.d);
        let z = -y / u;
        (z.is_finite() && z > 0.0).then_some(z)
    }

    /// The entrance pupil (the stop as seen from the front, paraxially): its radius and its
    /// axial position, mm from the front vertex.
    pub fn entrance_pupil(&self) -> (f64, f64) {
        let m = self.abcd(self.stop);
        // A ray parallel to the axis at height y meets the stop at a·y, so the stop's edge
        // takes y = its radius / a. One crossing the front plane at height y with slope u
        // meets the stop at a·y + b·u, at its centre when y = -b·u / a: it crossed the axis
        // at z = -y / u = b / a, the pupil's place.
        let radius = 0.5 * self.surfaces[self.stop].aperture / m.a.abs();
        (radius, m.b / m.a)
    }

    /// The f-number: focal length over the entrance pupil's diameter.
    pub fn f_number(&self) -> f64 {
        self.efl() / (2.0 * self.entrance_pupil().0)
    }

    /// The chief ray of light from infinity at `theta` radians off the axis (in the x–z
    /// plane, travelling toward +x): the ray through the stop's centre, with apertures
    /// ignored; `None` where no such ray gets through the glass (it misses a surface or
    /// reflects). See [`Prescription::chief_rays`].
    pub fn chief_ray(&self, theta: f64) -> Option<Ray> {
        self.chief_rays(&[theta]).pop().flatten()
    }

    /// The chief rays at `thetas` (increasing, radians, below 90°), as
    /// [`Prescription::chief_ray`]: found by Newton's method on their height at the front
    /// vertex's plane, continued from the axis a degree at a time (a fisheye's pupil moves
    /// far from its paraxial place at wide angles, where the paraxial guess would miss the
    /// glass). Past an angle with none, none.
    pub fn chief_rays(&self, thetas: &[f64]) -> Vec<Option<Ray>> {
        let m = self.abcd(self.stop);
        // The last angle solved, and its chief ray's height at the front plane.
        let (mut at, mut h) = (0.0, Some(0.0));
        thetas
            .iter()
            .map(|&theta| {
                if !(at..FRAC_PI_2).contains(&theta) {
                    h = None;
                }
                if let Some(mut current) = h {
                    let steps = ((theta - at).to_degrees().ceil() as usize).max(1);
                    for k in 1..=steps {
                        let t = at + (theta - at) * k as f64 / steps as f64;
                        // Off the axis, the paraxial chief ray's height starts the search.
                        let start = if at == 0.0 && k == 1 {
                            -m.b / m.a * t.tan()
                        } else {
                            current
                        };
                        match self.chief_height(t, start) {
                            Some(next) => current = next,
                            None => {
                                h = None;
                                break;
                            }
                        }
                    }
                    if h.is_some() {
                        h = Some(current);
                    }
                    at = theta;
                }
                let direction = DVec3::new(theta.sin(), 0.0, theta.cos());
                h.map(|h| self.ray_through_front_plane(h, direction))
            })
            .collect()
    }

    /// The ray of direction `direction` that crosses the front vertex's plane at height `h`
    /// (in x), starting in front of the lens.
    fn ray_through_front_plane(&self, h: f64, direction: DVec3) -> Ray {
        Ray {
            origin: DVec3::new(h, 0.0, 0.0) - self.start_distance(direction) * direction,
            direction,
        }
    }

    /// The front-plane height of the chief ray at `theta`, by Newton's method from `h`.
    fn chief_height(&self, theta: f64, mut h: f64) -> Option<f64> {
        let direction = DVec3::new(theta.sin(), 0.0, theta.cos());
        let at_stop = |h: f64| -> Option<f64> {
            let ray = self.ray_through_front_plane(h, direction);
            let r = self.trace_range(ray, 0, self.stop + 1, false).ok()?;
            Some(r.origin.x)
        };
        let scale = self.surfaces[0].aperture;
        let mut g = at_stop(h)?;
        for _ in 0..60 {
            if g.abs() <= 1e-12 * scale {
                return Some(h);
            }
            let step = 1e-7 * scale;
            let slope = (at_stop(h + step)? - at_stop(h - step)?) / (2.0 * step);
            if slope == 0.0 || !slope.is_finite() {
                return None;
            }
            // Halve the step until it lands on a traceable ray that is closer.
            let mut delta = -g / slope;
            loop {
                match at_stop(h + delta) {
                    Some(next) if next.abs() < g.abs() => {
                        h += delta;
                        g = next;
                        break;
                    }
                    _ if delta.abs() > 1e-15 * scale => delta *= 0.5,
                    _ => return (g.abs() <= 1e-9 * scale).then_some(h),
                }
            }
        }
        (g.abs() <= 1e-9 * scale).then_some(h)
    }

    /// Where the chief rays at `thetas` (increasing, radians) meet a film `film` mm behind
    /// the rear vertex: their distances from the axis, mm (on the side the light travels
    /// toward, the image being inverted); apertures ignored.
    pub fn image_heights(&self, thetas: &[f64], film: f64) -> Vec<Option<f64>> {
        let z = self.rear_vertex() + film;
        self.chief_rays(thetas)
            .into_iter()
            .map(|chief| {
                let out = self
                    .trace_range(chief?, 0, self.surfaces.len(), false)
                    .ok()?;
                (out.direction.z > 0.0)
                    .then(|| out.origin.x + (z - out.origin.z) * out.direction.x / out.direction.z)
            })
            .collect()
    }

    /// [`Prescription::image_heights`] at one angle.
    pub fn image_height(&self, theta: f64, film: f64) -> Option<f64> {
        self.image_heights(&[theta], film).pop().flatten()
    }

    /// How far back along `direction` from the front plane a ray starts: in front of the
    /// front surface, whose sag is at most half its aperture.
    fn start_distance(&self, direction: DVec3) -> f64 {
        (self.surfaces[0].aperture + 1.0) / direction.z
    }

    /// Whether any ray of light from infinity at `theta` radians off the axis gets through
    /// every aperture: `samples` rays in the x–z plane, evenly across the heights at the
    /// front plane that can meet the front surface.
    pub fn passes(&self, theta: f64, samples: usize) -> bool {
        let direction = DVec3::new(theta.sin(), 0.0, theta.cos());
        if direction.z <= 0.0 {
            return false;
        }
        // The front surface lies within half its aperture of the axis and of the front
        // plane (its sag is at most half its aperture, the radius being at least that), so
        // the rays that meet it cross the front plane within this of the axis.
        let reach = 0.5 * self.surfaces[0].aperture * (1.0 + theta.tan()) + 1.0;
        (0..samples).any(|i| {
            let h = -reach + 2.0 * reach * (i as f64 + 0.5) / samples as f64;
            self.trace(self.ray_through_front_plane(h, direction))
                .is_ok()
        })
    }

    /// Half the field of view any ray still gets through, radians (below 90°: light from
    /// behind the front vertex's plane is not traced), by bisection to 1e-6 rad.
    pub fn half_field(&self) -> f64 {
        let samples = 2001;
        let (mut lo, mut hi) = (0.0, 89.9f64.to_radians());
        if self.passes(hi, samples) {
            return hi;
        }
        while hi - lo > 1e-6 {
            let mid = 0.5 * (lo + hi);
            if self.passes(mid, samples) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }
}

/// Where the ray from `o` along unit `d` (in a surface's vertex frame) meets the surface of
/// `radius` (0: the plane z = 0), and the unit normal there facing the incoming light (−z
/// near the axis). Of a sphere's two intersections, the one on the vertex's cap, by the
/// stable form of the quadratic (no difference of nearly equal numbers).
fn intersect(o: DVec3, d: DVec3, radius: f64) -> Option<(f64, DVec3)> {
    if d.z <= 0.0 {
        return None;
    }
    if radius == 0.0 {
        let t = -o.z / d.z;
        return (t >= 0.0).then_some((t, DVec3::NEG_Z));
    }
    // |o + t d - (0, 0, R)|² = R² is t² + 2 b t + c = 0 with these, where c has no R² term
    // to cancel.
    let b = o.dot(d) - radius * d.z;
    let c = o.dot(o) - 2.0 * radius * o.z;
    let discriminant = b * b - c;
    if discriminant < 0.0 {
        return None;
    }
    // Travelling toward +z, the vertex's cap is met first when the centre is behind it
    // (radius > 0): t = -b - sign(R) √D; q is the root of larger magnitude, c / q the other.
    let q = -(b + b.signum() * discriminant.sqrt());
    let t = if b.signum() == radius.signum() {
        q
    } else if q != 0.0 {
        c / q
    } else {
        0.0
    };
    if t < 0.0 {
        return None;
    }
    let p = o + t * d;
    let normal = DVec3::new(p.x / radius, p.y / radius, p.z / radius - 1.0);
    Some((t, normal.normalize()))
}

/// Snell's law in vector form: unit `d` through a surface with unit `normal` (either side),
/// `eta` the ratio of the indices before and after; `None` on total internal reflection.
fn refract(d: DVec3, normal: DVec3, eta: f64) -> Option<DVec3> {
    let n = if normal.dot(d) > 0.0 { -normal } else { normal };
    let cos_i = -n.dot(d);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    Some((eta * d + (eta * cos_i - k.sqrt()) * n).normalize())
}
