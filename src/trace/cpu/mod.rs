//! The f64 reference tracer, the ground truth for the GPU's.
//!
//! It sees exactly the data the GPU sees (camera-relative vertices, lights and camera axes
//! rounded to f32 once, then promoted), shades with the same Whitted model, but computes in
//! f64 and finds hits with its own binary BVHs (median splits; independent of obvhs), itself
//! tested against brute force: one over the world's triangles, one per mesh, and one over the
//! instances that place meshes, whose rays it maps into the mesh's space with the f32 maps the
//! GPU gets. Rays come from the f64 lens reference.

mod affine;
mod surface;

pub(super) use surface::srgb_to_linear;

use affine::*;
use glam::{DMat3, DVec2, DVec3, Vec3};
use surface::*;

use crate::bvh::binary::Tree;

use super::{MAX_DEPTH_LIMIT, MAX_SHADOW_LAYERS, NO_HIT, RenderOutput};
use crate::lens::LensCamera;
use crate::scene::{Features, Scene, Surface, Texture};

/// Rays whose weight falls below this are not traced (as on the GPU).
const MIN_WEIGHT: f64 = crate::shared::MIN_WEIGHT as f64;

/// A hit: distance, barycentric weights of corners 1 and 2, scene triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray (the world's, in an instance too).
    pub t: f64,
    /// Weight of corner 1.
    pub u: f64,
    /// Weight of corner 2.
    pub v: f64,
    /// Scene triangle index (as ids name it).
    pub triangle: u32,
    /// The stored triangle (`Scene::triangles`).
    pub stored: u32,
    /// The instance it was hit in (index into `Scene::instances`), if any.
    pub instance: Option<u32>,
}

/// An instance as the reference uses it: the f32 maps the GPU gets, promoted.
struct Placed {
    to_mesh: Affine,
    to_world: Affine,
    normal: DMat3,
    /// Index into `Reference::meshes`.
    mesh: usize,
    id_base: u32,
    first: u32,
}

/// The reference tracer for one scene.
pub struct Reference<'a> {
    scene: &'a Scene,
    features: Features,
    /// Stored triangles' corners, f32-rounded then promoted: world ones camera-relative, mesh
    /// ones in their mesh's space.
    corners: Vec<[DVec3; 3]>,
    /// The BVH of the world's triangles, then one per mesh.
    meshes: Vec<Tree>,
    /// The instances, and the BVH over their boxes (empty for a flat scene).
    instances: Vec<Placed>,
    top: Tree,
    rotation: DMat3,
    lights: Vec<(bool, DVec3, DVec3)>,
    max_depth: u32,
    /// Each texture's mip levels after the first (`super::mip_levels`), if textures show.
    mips: Vec<Vec<Texture>>,
}

fn round32(v: DVec3) -> DVec3 {
    v.as_vec3().as_dvec3()
}

fn v3(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

impl<'a> Reference<'a> {
    /// Prepares the reference for `scene`, relative to its camera as the GPU upload is.
    pub fn new(scene: &'a Scene, max_depth: u32) -> Self {
        assert!(max_depth <= MAX_DEPTH_LIMIT);
        let origin = scene.camera.position;
        let world = scene.world_triangles;
        let corners: Vec<[DVec3; 3]> = scene
            .triangles
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let shift = if i < world { origin } else { DVec3::ZERO };
                t.map(|p| round32(p - shift))
            })
            .collect();
        let triangle_box = |i: u32| {
            let c = corners[i as usize];
            (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]))
        };
        let mut meshes = vec![Tree::new((0..world as u32).collect(), &triangle_box)];
        let mut mesh_of = std::collections::HashMap::new();
        let mut instances = Vec::new();
        let mut boxes = Vec::new();
        let mut id_base = world as u32;
        for instance in &scene.instances {
            let mesh = *mesh_of.entry(instance.first).or_insert_with(|| {
                let ids = (instance.first..instance.first + instance.count).collect();
                meshes.push(Tree::new(ids, &triangle_box));
                meshes.len() - 1
            });
            let gpu =
                crate::bvh::gpu_instance(instance.transform, origin, 0, id_base, instance.first);
            let row = |r: [f32; 3]| DVec3::new(r[0].into(), r[1].into(), r[2].into());
            instances.push(Placed {
                to_mesh: Affine::from_rows(gpu.to_mesh),
                to_world: Affine::from_rows(gpu.to_world),
                normal: DMat3::from_cols(row(gpu.normal_x), row(gpu.normal_y), row(gpu.normal_z))
                    .transpose(),
                mesh,
                id_base,
                first: instance.first,
            });
            // The mesh's box through the f32 map, padded by far more than its roundings.
            let (lo, hi) = crate::scene::placed_bounds(
                &scene.triangles[instance.first as usize..][..instance.count as usize],
                instance.transform,
            )
            .unwrap_or((DVec3::INFINITY, DVec3::NEG_INFINITY));
            let pad =
                DVec3::splat(1e-5 * (lo - origin).abs().max((hi - origin).abs()).max_element());
            boxes.push((lo - origin - pad, hi - origin + pad));
            id_base += instance.count;
        }
        let top = Tree::new((0..instances.len() as u32).collect(), &|k| {
            boxes[k as usize]
        });
        let rotation = scene.camera.rotation();
        let rotation = DMat3::from_cols(
            round32(rotation.x_axis),
            round32(rotation.y_axis),
            round32(rotation.z_axis),
        );
        let lights = scene
            .lights
            .iter()
            .map(|l| {
                let (point, vector, colour) = l.relative_to(origin);
                (point, vector.as_dvec3(), colour.as_dvec3())
            })
            .collect();
        let features = scene.features();
        let mips = match features.textures {
            true => scene.textures.iter().map(super::mip_levels).collect(),
            false => Vec::new(),
        };
        Self {
            scene,
            features,
            mips,
            corners,
            meshes,
            instances,
            top,
            rotation,
            lights,
            max_depth,
        }
    }

    /// Watertight ray/triangle test (Woop, Benthin and Wald 2013) in f64, edges inclusive, for
    /// t in (tmin, tmax]; the hit is scene triangle `id`.
    fn triangle_hit(
        &self,
        stored: u32,
        id: u32,
        origin: DVec3,
        dir: DVec3,
        (tmin, tmax): (f64, f64),
    ) -> Option<Hit> {
        let kz = dir.abs().max_position();
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let (sx, sy, sz) = (dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
        let [a, b, c] = self.corners[stored as usize].map(|p| p - origin);
        let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
        let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
        let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t = (u * a[kz] + v * b[kz] + w * c[kz]) * sz / det;
        (t > tmin && t <= tmax).then_some(Hit {
            t,
            u: v / det,
            v: w / det,
            triangle: id,
            stored,
            instance: None,
        })
    }

    /// Tests the ray (in mesh `mesh`'s space) against the mesh, keeping the best hit in
    /// `best`; true where `any` and something was hit.
    #[allow(clippy::too_many_arguments)]
    fn trace_mesh(
        &self,
        mesh: usize,
        instance: Option<u32>,
        origin: DVec3,
        dir: DVec3,
        (tmin, tmax): (f64, f64),
        any: bool,
        best: &std::cell::Cell<Option<Hit>>,
    ) -> bool {
        let id = |stored: u32| match instance {
            Some(k) => {
                let p = &self.instances[k as usize];
                p.id_base + stored - p.first
            }
            None => stored,
        };
        let limit = || best.get().map_or(tmax, |h| h.t);
        let mut found = false;
        self.meshes[mesh].walk(origin, dir, tmin, &limit, &mut |stored| {
            if let Some(mut hit) =
                self.triangle_hit(stored, id(stored), origin, dir, (tmin, limit()))
                && closer(&hit, best.get().as_ref(), tmax)
            {
                hit.instance = instance;
                best.set(Some(hit));
                found = true;
            }
            any && found
        });
        any && found
    }

    /// The closest hit in (tmin, tmax), or with `any` the first one found.
    pub fn trace(&self, origin: DVec3, dir: DVec3, tmin: f64, tmax: f64, any: bool) -> Option<Hit> {
        let best = std::cell::Cell::new(None);
        // The world's triangles, then the instances.
        if self.trace_mesh(0, None, origin, dir, (tmin, tmax), any, &best)
            || self.instances.is_empty()
        {
            return best.get();
        }
        let limit = || best.get().map_or(tmax, |h: Hit| h.t);
        self.top.walk(origin, dir, tmin, &limit, &mut |k| {
            let p = &self.instances[k as usize];
            let local_origin = p.to_mesh.m * origin + p.to_mesh.t;
            let local_dir = p.to_mesh.m * dir;
            self.trace_mesh(
                p.mesh,
                Some(k),
                local_origin,
                local_dir,
                (tmin, tmax),
                any,
                &best,
            )
        });
        best.get()
    }

    /// Brute force over every scene triangle (to test [`Reference::trace`]).
    pub fn trace_brute_force(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let best = std::cell::Cell::new(None);
        let test = |stored: u32, id: u32, instance: Option<u32>, o: DVec3, d: DVec3| {
            let limit = best.get().map_or(f64::INFINITY, |h: Hit| h.t);
            if let Some(mut hit) = self.triangle_hit(stored, id, o, d, (0.0, limit))
                && closer(&hit, best.get().as_ref(), f64::INFINITY)
            {
                hit.instance = instance;
                best.set(Some(hit));
            }
        };
        for stored in 0..self.scene.world_triangles as u32 {
            test(stored, stored, None, origin, dir);
        }
        for (k, p) in self.instances.iter().enumerate() {
            let count = self.scene.instances[k].count;
            let (o, d) = (p.to_mesh.m * origin + p.to_mesh.t, p.to_mesh.m * dir);
            for j in 0..count {
                test(p.first + j, p.id_base + j, Some(k as u32), o, d);
            }
        }
        best.get()
    }

    /// Renders every pixel of `camera` with one ray through its centre (rows split over the
    /// machine's threads).
    pub fn render(&self, camera: &LensCamera) -> RenderOutput {
        self.render_samples(camera, 1)
    }

    /// As [`Reference::render`] with `samples_per_side`² rays per pixel, placed as the GPU
    /// places them ([`super::sampling`]): the colour is their mean over those the lens covers,
    /// `w` the covered share; geometry and ids stay the centre ray's.
    pub fn render_samples(&self, camera: &LensCamera, samples_per_side: u32) -> RenderOutput {
        let size = camera.size;
        let directions = camera.directions();
        let mut pixels = vec![([0.0f32; 4], [0.0f32; 4], NO_HIT); directions.len()];
        crate::threads::in_parts(&mut pixels, |first, out| {
            for (j, (o, d)) in out.iter_mut().zip(&directions[first..]).enumerate() {
                let index = first + j;
                let width = size.width as usize;
                let centre = DVec2::new((index % width) as f64, (index / width) as f64) + 0.5;
                *o = match d {
                    Some(d) => self.pixel(self.rotation * *d, self.spread(camera, centre, *d, 1.0)),
                    None => ([0.0; 4], [0.0; 4], NO_HIT),
                };
                if samples_per_side > 1 {
                    o.0 = self.samples(camera, index, samples_per_side);
                }
            }
        });
        RenderOutput {
            size,
            colour: pixels.iter().map(|p| p.0).collect(),
            geometry: pixels.iter().map(|p| p.1).collect(),
            ids: pixels.iter().map(|p| p.2).collect(),
        }
    }

    /// The mean colour of pixel `index`'s samples that have a ray, with w their share.
    fn samples(&self, camera: &LensCamera, index: usize, side: u32) -> [f32; 4] {
        let width = camera.size.width as usize;
        let corner = DVec2::new((index % width) as f64, (index / width) as f64);
        let (mut sum, mut covered) = (DVec3::ZERO, 0);
        for k in 0..side * side {
            let p = corner + super::sampling::sample_offset(index as u32, k, side);
            if let Some(d) = camera.unproject(p) {
                let spread = self.spread(camera, p, d, 1.0 / f64::from(side));
                let c = self.pixel(self.rotation * d, spread).0;
                sum += DVec3::new(c[0].into(), c[1].into(), c[2].into());
                covered += 1;
            }
        }
        if covered == 0 {
            return [0.0; 4];
        }
        let c = (sum / f64::from(covered)).as_vec3();
        [c.x, c.y, c.z, covered as f32 / (side * side) as f32]
    }

    /// How the camera-space direction `d` of image point `p` changes a step of `step` pixels
    /// right and down (or from a step back where the lens masks the one ahead; zero where it
    /// masks both), in the world: the primary ray's differentials, as `wgsl/pixel.wgsl`'s
    /// `set_spread` makes them (only where textures show).
    fn spread(&self, camera: &LensCamera, p: DVec2, d: DVec3, step: f64) -> [DVec3; 2] {
        if !self.features.textures {
            return [DVec3::ZERO; 2];
        }
        camera
            .steps(p, d, step)
            .map(|change| self.rotation * change)
    }

    /// The level of detail of the texture at `hit` of a primary ray along `dir` whose
    /// differentials are `spread`, as `wgsl/surface.wgsl`'s `texture_lod` takes it from
    /// `wgsl/shade.wgsl`'s `hit_footprint`: the hit's moves on its plane, into barycentric
    /// steps by the triangle's dual basis (in its mesh's space), into texels by its UVs; log2
    /// of the square root of the footprint's area in texels, 0 below one texel.
    fn texture_lod(&self, dir: DVec3, hit: &Hit, spread: [DVec3; 2]) -> f64 {
        let i = hit.stored as usize;
        let m = &self.scene.materials[self.scene.material_of[i] as usize];
        let Some(t) = m.diffuse_texture.filter(|_| self.features.textures) else {
            return 0.0;
        };
        let t = &self.scene.textures[t as usize];
        let [a, b, c] = self.corners[i];
        let placed = hit.instance.map(|k| &self.instances[k as usize]);
        let n = (b - a).cross(c - a);
        let world_n = placed.map_or(n, |p| p.normal * n);
        let steps = spread.map(|x| {
            let on_plane = hit.t * (x - x.dot(world_n) / dir.dot(world_n) * dir);
            placed.map_or(on_plane, |p| p.to_mesh.m * on_plane)
        });
        let dual = [(c - a).cross(n), n.cross(b - a)].map(|e| e / n.length_squared());
        let uv = self.scene.uvs.as_ref().expect("textures need UVs")[i].map(|v| v.as_dvec2());
        let size = DVec2::new(t.width.into(), t.height.into());
        let texels = steps
            .map(|s| (dual[0].dot(s) * (uv[1] - uv[0]) + dual[1].dot(s) * (uv[2] - uv[0])) * size);
        let area = texels[0].perp_dot(texels[1]).abs();
        if area > 1.0 { 0.5 * area.log2() } else { 0.0 }
    }

    /// One primary ray (world direction from the camera, its differentials `spread`): colour
    /// with w = 1, geometry, id.
    fn pixel(&self, dir: DVec3, spread: [DVec3; 2]) -> ([f32; 4], [f32; 4], u32) {
        let mut colour = DVec3::ZERO;
        let mut first = ([0.0f32; 4], NO_HIT);
        let mut stack = vec![(DVec3::ZERO, dir, DVec3::ONE, 0u32)];
        while let Some((origin, dir, weight, depth)) = stack.pop() {
            let Some(hit) = self.trace(origin, dir, 0.0, f64::INFINITY, false) else {
                colour += weight * v3(self.scene.sky);
                continue;
            };
            let lod = match depth {
                0 => self.texture_lod(dir, &hit, spread),
                _ => 0.0,
            };
            let s = self.surface(dir, &hit, lod);
            if depth == 0 {
                let n = s.normal.as_vec3();
                first = ([n.x, n.y, n.z, hit.t as f32], hit.triangle);
            }
            let m = &self.scene.materials[self.scene.material_of[hit.stored as usize] as usize];
            let children = depth < self.max_depth;
            let push = |stack: &mut Vec<_>, origin, dir, w: DVec3| {
                if children && w.max_element() >= MIN_WEIGHT {
                    stack.push((origin, dir, w, depth + 1));
                }
            };
            let offset = self.offset(&hit, s.position);
            let above = s.position + s.geometric * offset;
            let below = s.position - s.geometric * offset;
            let mut surface_weight = weight;
            if self.features.translucent && m.surface == Surface::Diffuse && m.opacity < 1.0 {
                let opacity = f64::from(m.opacity);
                push(&mut stack, below, dir, weight * (1.0 - opacity));
                surface_weight *= opacity;
            }
            colour += surface_weight * v3(m.emission);
            match m.surface {
                Surface::Mirror if self.features.mirrors => {
                    push(
                        &mut stack,
                        above,
                        keep_side(reflect(dir, s.normal), s.geometric, 1.0),
                        weight * v3(m.specular),
                    );
                }
                Surface::Glass if self.features.glass => {
                    let eta = if s.front {
                        1.0 / f64::from(m.ior)
                    } else {
                        f64::from(m.ior)
                    };
                    let cos_i = -dir.dot(s.normal);
                    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
                    let mut reflectance = 1.0;
                    if sin2_t < 1.0 {
                        let cos_t = (1.0 - sin2_t).sqrt();
                        reflectance = fresnel(cos_i, cos_t, 1.0 / eta);
                        let refracted = (eta * dir + (eta * cos_i - cos_t) * s.normal).normalize();
                        let w = weight * (1.0 - reflectance) * v3(m.transmission);
                        push(
                            &mut stack,
                            below,
                            keep_side(refracted, s.geometric, -1.0),
                            w,
                        );
                    }
                    push(
                        &mut stack,
                        above,
                        keep_side(reflect(dir, s.normal), s.geometric, 1.0),
                        weight * reflectance,
                    );
                }
                _ => colour += surface_weight * self.direct_light(&s, dir, above),
            }
        }
        let c = colour.as_vec3();
        ([c.x, c.y, c.z, 1.0], first.0, first.1)
    }

    /// How far rays leaving `hit` (at `p`) start off its surface: by far more than f64's
    /// roundings; off an instance's, by more than the round trip of its f32 maps (a few 1e-8
    /// of the reach of the point and of the instance's translation), since those rays are
    /// mapped into its space again.
    fn offset(&self, hit: &Hit, p: DVec3) -> f64 {
        let reach = 1.0 + p.length();
        match hit.instance {
            Some(k) => 1e-6 * (reach + self.instances[k as usize].to_world.t.length()),
            None => 1e-9 * reach,
        }
    }

    /// The surface at `hit` of a ray along `dir`, its texture filtered at level of detail `lod`.
    fn surface(&self, dir: DVec3, hit: &Hit, lod: f64) -> SurfacePoint {
        let i = hit.stored as usize;
        let [a, b, c] = self.corners[i];
        let w = 1.0 - hit.u - hit.v;
        let placed = hit.instance.map(|k| &self.instances[k as usize]);
        let (to_world, normal_matrix) = match placed {
            Some(p) => (p.to_world, p.normal),
            None => (
                Affine {
                    m: DMat3::IDENTITY,
                    t: DVec3::ZERO,
                },
                DMat3::IDENTITY,
            ),
        };
        let position = to_world.m * (w * a + hit.u * b + hit.v * c) + to_world.t;
        let mut geometric = (normal_matrix * (b - a).cross(c - a)).normalize();
        let front = geometric.dot(dir) < 0.0;
        if !front {
            geometric = -geometric;
        }
        let mut normal = geometric;
        if self.features.smooth_normals {
            let n = self.scene.normals.as_ref().unwrap()[i];
            // Each vertex normal in the world before interpolation, as a flattened copy has
            // it.
            let n = n.map(|n| match placed {
                Some(_) => (normal_matrix * v3(n)).normalize(),
                None => v3(n),
            });
            let n = (w * n[0] + hit.u * n[1] + hit.v * n[2]).normalize();
            normal = if n.dot(geometric) >= 0.0 { n } else { -n };
        }
        let m = &self.scene.materials[self.scene.material_of[i] as usize];
        let mut diffuse = v3(m.diffuse);
        if let (true, Some(t)) = (self.features.textures, m.diffuse_texture) {
            let uv = self.scene.uvs.as_ref().unwrap()[i];
            let uv = w * uv[0].as_dvec2() + hit.u * uv[1].as_dvec2() + hit.v * uv[2].as_dvec2();
            diffuse *= trilinear(
                &self.scene.textures[t as usize],
                &self.mips[t as usize],
                uv,
                lod,
            );
        }
        SurfacePoint {
            position,
            geometric,
            normal,
            front,
            diffuse,
            specular: v3(m.specular),
            shininess: f64::from(m.shininess),
        }
    }

    fn direct_light(&self, s: &SurfacePoint, view: DVec3, origin: DVec3) -> DVec3 {
        let mut colour = s.diffuse * v3(self.scene.ambient);
        for &(point, vector, light) in &self.lights {
            let (to_light, distance, irradiance) = if point {
                let d = vector - origin;
                let distance = d.length();
                (d / distance, distance, light / (distance * distance))
            } else {
                (-vector, f64::INFINITY, light)
            };
            let cos_light = s.normal.dot(to_light);
            if cos_light <= 0.0 || s.geometric.dot(to_light) <= 0.0 {
                continue;
            }
            let transmittance = self.shadow_transmittance(origin, to_light, distance);
            if transmittance == 0.0 {
                continue;
            }
            let irradiance = irradiance * transmittance;
            let half = (to_light - view).normalize();
            let highlight = s.specular * s.normal.dot(half).max(0.0).powf(s.shininess);
            colour += irradiance * (s.diffuse * cos_light + highlight);
        }
        colour
    }
}

impl Reference<'_> {
    /// As a shadow ray of `shade` in `wgsl/shade.wgsl` (`shadow_goes_on`): the product of
    /// (1 - opacity) over the partially transparent diffuse surfaces between `origin` and the
    /// light.
    fn shadow_transmittance(&self, origin: DVec3, to_light: DVec3, distance: f64) -> f64 {
        if !self.features.translucent {
            return match self.trace(origin, to_light, 0.0, distance, true) {
                Some(_) => 0.0,
                None => 1.0,
            };
        }
        let (mut o, mut remaining, mut transmittance) = (origin, distance, 1.0);
        for layer in 0..=MAX_SHADOW_LAYERS {
            let Some(hit) = self.trace(o, to_light, 0.0, remaining, false) else {
                return transmittance;
            };
            let m = &self.scene.materials[self.scene.material_of[hit.stored as usize] as usize];
            transmittance *= 1.0 - f64::from(m.opacity);
            if m.surface != Surface::Diffuse
                || transmittance < MIN_WEIGHT
                || layer == MAX_SHADOW_LAYERS
            {
                return 0.0;
            }
            let p = o + to_light * hit.t;
            o = p + to_light * self.offset(&hit, p);
            remaining -= hit.t;
        }
        0.0
    }
}

/// Whether `hit` beats `best` (or, without one, lies before `tmax`): nearer, or as near and of
/// a lower scene triangle, as `bvh_trace` in `wgsl/bvh.wgsl` decides exact ties.
fn closer(hit: &Hit, best: Option<&Hit>, tmax: f64) -> bool {
    match best {
        None => hit.t < tmax,
        Some(b) => hit.t < b.t || (hit.t == b.t && hit.triangle < b.triangle),
    }
}
