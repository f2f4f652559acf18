//! Assembles scenes from triangles and simple shapes (quads, boxes, spheres, tori).

use std::f64::consts::{PI, TAU};

use glam::{DAffine3, DVec3, Vec2, Vec3};

use super::animation::Animation;
use super::{Camera, Instance, Light, Material, Object, Scene, Texture, face_normal};

/// Collects triangles with their materials, normals and UVs, then makes a [`Scene`].
#[derive(Default)]
pub struct MeshBuilder {
    triangles: Vec<[DVec3; 3]>,
    normals: Vec<Option<[Vec3; 3]>>,
    uvs: Vec<Option<[Vec2; 3]>>,
    material_of: Vec<u32>,
    materials: Vec<Material>,
    textures: Vec<Texture>,
    /// Meshes for instances: ranges `(first, count)` of the triangles above, in mesh space.
    meshes: Vec<(usize, usize)>,
    /// Instances: a mesh, its transform to world space, its object's label and its
    /// animation (an index into `animations`).
    placed: Vec<(usize, DAffine3, Option<u32>, Option<u32>)>,
    animations: Vec<Animation>,
    /// The labels [`MeshBuilder::object`] gave, and the one triangles are added under.
    labels: Vec<Object>,
    label_of: Vec<Option<u32>>,
    current: Option<u32>,
}

/// A mesh [`MeshBuilder::place`] can place (see [`MeshBuilder::mesh_since`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshId(usize);

impl MeshBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// A builder that starts with these materials and textures.
    pub fn with_materials(materials: Vec<Material>, textures: Vec<Texture>) -> Self {
        Self {
            materials,
            textures,
            ..Self::default()
        }
    }

    /// Makes the triangles from index `first` on a mesh, in its own space: they are in the
    /// scene only where [`MeshBuilder::place`] places them, stored once however often.
    pub fn mesh_since(&mut self, first: usize) -> MeshId {
        self.meshes.push((first, self.triangles.len() - first));
        MeshId(self.meshes.len() - 1)
    }

    /// Places `mesh` in the world by `transform`. Returns false (nothing placed) where the
    /// transform is not finite or flattens the mesh (a singular 3×3 part).
    pub fn place(&mut self, mesh: MeshId, transform: DAffine3) -> bool {
        let det = transform.matrix3.determinant();
        if !(transform.is_finite() && det.is_normal() && transform.inverse().is_finite()) {
            return false;
        }
        self.placed.push((mesh.0, transform, self.current, None));
        true
    }

    /// Places `mesh` where `animation` puts it at each scene time (at time 0 until a
    /// renderer asks for another: [`Scene::at`]). Returns false (nothing placed) where a
    /// placement at one of its key times is not finite. A placement that flattens the mesh at
    /// some time (a key scaling it to zero, as animations do to hide things) hides it then.
    pub fn place_moving(&mut self, mesh: MeshId, animation: Animation) -> bool {
        let times = animation.key_times();
        if !times
            .iter()
            .chain([&0.0])
            .all(|&t| animation.at(t).is_finite())
        {
            return false;
        }
        let transform = animation.at(0.0);
        self.animations.push(animation);
        let index = self.animations.len() as u32 - 1;
        self.placed
            .push((mesh.0, transform, self.current, Some(index)));
        true
    }

    /// Names the object the triangles added (and the meshes placed) from now on belong to,
    /// and its class: each call is an object of its own (each placement of a mesh too), for
    /// the instance and semantic outputs. Triangles added before any call are labelled by
    /// their material's name.
    pub fn object(&mut self, name: &str, class: &str) {
        self.labels.push(Object {
            name: name.to_string(),
            class: class.to_string(),
        });
        self.current = Some(self.labels.len() as u32 - 1);
    }

    /// Adds a material and returns its index.
    pub fn material(&mut self, material: Material) -> u32 {
        self.materials.push(material);
        self.materials.len() as u32 - 1
    }

    /// Adds a texture and returns its index.
    pub fn texture(&mut self, texture: Texture) -> u32 {
        self.textures.push(texture);
        self.textures.len() as u32 - 1
    }

    /// Number of materials so far.
    pub fn material_count(&self) -> u32 {
        self.materials.len() as u32
    }

    /// Number of textures so far.
    pub fn texture_count(&self) -> u32 {
        self.textures.len() as u32
    }

    /// The world bounds of the triangles so far: those of no mesh, and the placed meshes
    /// (`None` if there are none).
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        if self.meshes.is_empty() {
            return super::bounds(&self.triangles);
        }
        let in_mesh = self.in_meshes(0);
        let world: Vec<[DVec3; 3]> = (0..self.triangles.len())
            .filter(|&i| !in_mesh[i])
            .map(|i| self.triangles[i])
            .collect();
        self.placed
            .iter()
            .fold(super::bounds(&world), |acc, &(m, t, _, _)| {
                let (first, count) = self.meshes[m];
                super::union(
                    acc,
                    super::placed_bounds(&self.triangles[first..first + count], t),
                )
            })
    }

    /// Number of triangles so far.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether no triangle was added yet.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The materials so far, to override their fields.
    pub fn materials_mut(&mut self) -> &mut [Material] {
        &mut self.materials
    }

    /// Moves the triangles from index `first` on by `transform`: corners as points, normals by
    /// the inverse transpose. A mirroring transform swaps two corners so that faces keep their
    /// side. Meshes made from `first` on stay in their own space; their instances move instead.
    pub fn transform_since(&mut self, first: usize, transform: DAffine3) {
        let normal_matrix = transform.matrix3.inverse().transpose();
        let mirrored = transform.matrix3.determinant() < 0.0;
        let in_mesh = self.in_meshes(first);
        for (mesh, placed, _, animation) in &mut self.placed {
            if self.meshes[*mesh].0 >= first {
                *placed = transform * *placed;
                if let Some(a) = animation {
                    let factors = &mut self.animations[*a as usize].factors;
                    factors.insert(0, super::animation::Factor::Fixed(transform));
                }
            }
        }
        for i in (first..self.triangles.len()).filter(|&i| !in_mesh[i - first]) {
            let t = &mut self.triangles[i];
            *t = t.map(|p| transform.transform_point3(p));
            let n = &mut self.normals[i];
            if let Some(n) = n {
                *n = n.map(|n| (normal_matrix * n.as_dvec3()).normalize_or_zero().as_vec3());
            }
            if mirrored {
                t.swap(1, 2);
                if let Some(n) = n {
                    n.swap(1, 2);
                }
                if let Some(uv) = &mut self.uvs[i] {
                    uv.swap(1, 2);
                }
            }
        }
    }

    /// Gives the triangles from index `first` on the material `material`.
    pub fn set_material_since(&mut self, first: usize, material: u32) {
        for m in &mut self.material_of[first..] {
            *m = material;
        }
    }

    /// Adds one triangle.
    pub fn triangle(
        &mut self,
        corners: [DVec3; 3],
        normals: Option<[Vec3; 3]>,
        uvs: Option<[Vec2; 3]>,
        material: u32,
    ) {
        self.triangles.push(corners);
        self.normals.push(normals);
        self.uvs.push(uvs);
        self.material_of.push(material);
        self.label_of.push(self.current);
    }

    /// A parallelogram `corner + s·u + t·v`, s, t ∈ [0, 1], facing `u × v`, with UVs running
    /// from 0 to `uv_scale`.
    pub fn quad(&mut self, corner: DVec3, u: DVec3, v: DVec3, uv_scale: Vec2, material: u32) {
        let p = [corner, corner + u, corner + u + v, corner + v];
        let t = [
            Vec2::ZERO,
            Vec2::new(uv_scale.x, 0.0),
            uv_scale,
            Vec2::new(0.0, uv_scale.y),
        ];
        self.triangle([p[0], p[1], p[2]], None, Some([t[0], t[1], t[2]]), material);
        self.triangle([p[0], p[2], p[3]], None, Some([t[0], t[2], t[3]]), material);
    }

    /// An axis-aligned box with outward faces.
    pub fn cuboid(&mut self, lo: DVec3, hi: DVec3, material: u32) {
        let d = hi - lo;
        let (x, y, z) = (DVec3::X * d.x, DVec3::Y * d.y, DVec3::Z * d.z);
        let one = Vec2::ONE;
        self.quad(lo, y, x, one, material); // -z
        self.quad(lo + z, x, y, one, material); // +z
        self.quad(lo, z, y, one, material); // -x
        self.quad(lo + x, y, z, one, material); // +x
        self.quad(lo, x, z, one, material); // -y
        self.quad(lo + y, z, x, one, material); // +y
    }

    /// A closed UV sphere with smooth normals (`inward` flips them, for a camera inside).
    pub fn sphere(
        &mut self,
        centre: DVec3,
        radius: f64,
        segments: u32,
        rings: u32,
        inward: bool,
        material: u32,
    ) {
        let point = |i: u32, j: u32| {
            let (phi, theta) = (
                TAU * f64::from(i) / f64::from(segments),
                PI * f64::from(j) / f64::from(rings),
            );
            // Poles are exact so that the fans there close.
            let n = match j {
                0 => DVec3::Y,
                _ if j == rings => -DVec3::Y,
                _ => DVec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    -theta.sin() * phi.sin(),
                ),
            };
            (centre + n * radius, if inward { -n } else { n })
        };
        self.grid(segments, rings, inward, material, point);
    }

    /// A closed torus around the y axis with smooth normals.
    pub fn torus(
        &mut self,
        centre: DVec3,
        major: f64,
        minor: f64,
        segments: u32,
        sides: u32,
        material: u32,
    ) {
        let point = |i: u32, j: u32| {
            let (phi, psi) = (
                TAU * f64::from(i) / f64::from(segments),
                TAU * f64::from(j) / f64::from(sides),
            );
            let ring = DVec3::new(phi.cos(), 0.0, -phi.sin());
            let n = ring * psi.cos() + DVec3::Y * psi.sin();
            (centre + ring * major + n * minor, n)
        };
        self.grid(segments, sides, false, material, point);
    }

    /// Triangulates a (segments × rows) parametric grid closed in its first parameter.
    /// Vertices are shared by index arithmetic, so neighbouring triangles meet exactly.
    fn grid(
        &mut self,
        segments: u32,
        rows: u32,
        flip: bool,
        material: u32,
        point: impl Fn(u32, u32) -> (DVec3, DVec3),
    ) {
        let vertex = |i: u32, j: u32| point(i % segments, j);
        for j in 0..rows {
            for i in 0..segments {
                let a = vertex(i, j);
                let b = vertex(i + 1, j);
                let c = vertex(i + 1, j + 1);
                let d = vertex(i, j + 1);
                for tri in [[a, d, c], [a, c, b]] {
                    let mut tri = tri;
                    if flip {
                        tri.swap(1, 2);
                    }
                    let corners = tri.map(|(p, _)| p);
                    // Skip the zero-area triangles a grid makes at poles.
                    if face_normal(&corners) == DVec3::ZERO {
                        continue;
                    }
                    let normals = tri.map(|(_, n)| n.as_vec3());
                    self.triangle(corners, Some(normals), None, material);
                }
            }
        }
    }

    /// For each triangle from `first` on, whether it belongs to a mesh (made from `first` on)
    /// rather than to the world.
    fn in_meshes(&self, first: usize) -> Vec<bool> {
        let mut in_mesh = vec![false; self.triangles.len() - first];
        for &(start, count) in self.meshes.iter().filter(|m| m.0 >= first) {
            in_mesh[start - first..start - first + count].fill(true);
        }
        in_mesh
    }

    /// Instances placed so far.
    pub fn placed_count(&self) -> usize {
        self.placed.len()
    }

    /// The finished scene: world triangles first, then the placed meshes (a mesh no instance
    /// placed is left out).
    pub fn finish(self, lights: Vec<Light>, sky: Vec3, ambient: Vec3, camera: Camera) -> Scene {
        // The stored order: triangles of no mesh, then each placed mesh's.
        let in_mesh = self.in_meshes(0);
        let mut order: Vec<usize> = (0..self.triangles.len()).filter(|&i| !in_mesh[i]).collect();
        let world_triangles = order.len();
        let mut mesh_first = vec![None; self.meshes.len()];
        let mut instances = Vec::with_capacity(self.placed.len());
        // Objects: the labels as given (or a material's name where there is none); a placement
        // whose label the world or another placement took first gets a numbered copy.
        let mut objects: Vec<Object> = self.labels.clone();
        let mut claimed = vec![false; objects.len()];
        let mut by_material: Vec<Option<u32>> = vec![None; self.materials.len()];
        let mut of_material = |material: u32, objects: &mut Vec<Object>| {
            *by_material[material as usize].get_or_insert_with(|| {
                let name = &self.materials[material as usize].name;
                objects.push(Object {
                    name: name.clone(),
                    class: name.clone(),
                });
                objects.len() as u32 - 1
            })
        };
        let object_of: Vec<u32> = order
            .iter()
            .map(|&i| match self.label_of[i] {
                Some(l) => {
                    claimed[l as usize] = true;
                    l
                }
                None => of_material(self.material_of[i], &mut objects),
            })
            .collect();
        for &(mesh, transform, label, animation) in &self.placed {
            let (first, count) = self.meshes[mesh];
            let stored = *mesh_first[mesh].get_or_insert_with(|| {
                order.extend(first..first + count);
                order.len() - count
            });
            let object = match label {
                Some(l) if !claimed[l as usize] => {
                    claimed[l as usize] = true;
                    l
                }
                _ => {
                    let like = match label {
                        Some(l) => objects[l as usize].clone(),
                        None => {
                            let o = of_material(self.material_of[first], &mut objects);
                            objects[o as usize].clone()
                        }
                    };
                    objects.push(Object {
                        name: format!("{} {}", like.name, instances.len()),
                        class: like.class,
                    });
                    objects.len() as u32 - 1
                }
            };
            instances.push(Instance {
                first: stored as u32,
                count: count as u32,
                transform,
                object,
                animation,
            });
        }
        let normals = self.normals.iter().any(Option::is_some).then(|| {
            order
                .iter()
                .map(|&i| {
                    self.normals[i]
                        .unwrap_or_else(|| [face_normal(&self.triangles[i]).as_vec3(); 3])
                })
                .collect()
        });
        let uvs = self.uvs.iter().any(Option::is_some).then(|| {
            order
                .iter()
                .map(|&i| self.uvs[i].unwrap_or([Vec2::ZERO; 3]))
                .collect()
        });
        Scene {
            triangles: order.iter().map(|&i| self.triangles[i]).collect(),
            world_triangles,
            instances,
            normals,
            uvs,
            material_of: order.iter().map(|&i| self.material_of[i]).collect(),
            materials: self.materials,
            textures: self.textures,
            lights,
            sky,
            ambient,
            camera,
            camera_path: Vec::new(),
            cameras: Vec::new(),
            headlight: None,
            framed: None,
            objects,
            object_of,
            animations: self.animations,
        }
    }
}

/// A procedural checker texture: `cells` × `cells` squares of two sRGB colours, with thin grid
/// lines of a third (the first texel row and column of each cell) if `line` is given, `size`
/// texels square.
pub fn checker(
    name: &str,
    size: u32,
    cells: u32,
    a: [u8; 3],
    b: [u8; 3],
    line: Option<[u8; 3]>,
) -> Texture {
    let cell = size / cells;
    let mut rgba = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let c = if let Some(line) = line.filter(|_| x % cell == 0 || y % cell == 0) {
                line
            } else if (x / cell + y / cell).is_multiple_of(2) {
                a
            } else {
                b
            };
            rgba.extend_from_slice(&[c[0], c[1], c[2], 255]);
        }
    }
    Texture {
        name: name.to_string(),
        width: size,
        height: size,
        rgba,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Triangles added before any label are named by their material; labelled ones by their
    /// label; each placement of a mesh is an object of its own, the first taking the label
    /// and the rest numbered copies of the same class; ids map to them through
    /// `Scene::objects_of` (a miss to `NO_OBJECT`), and classes are listed once each.
    #[test]
    fn objects_come_from_labels_or_materials_and_each_placement_is_one() {
        let mut b = MeshBuilder::new();
        let red = b.material(Material::diffuse("red", Vec3::X));
        let (x, y) = (DVec3::X, DVec3::Y);
        b.quad(DVec3::ZERO, x, y, Vec2::ONE, red);
        b.object("chair", "furniture");
        b.quad(DVec3::Z, x, y, Vec2::ONE, red);
        let first = b.len();
        b.quad(DVec3::ZERO, x, y, Vec2::ONE, red);
        let mesh = b.mesh_since(first);
        b.object("cup", "tableware");
        for k in 0..2 {
            assert!(b.place(mesh, DAffine3::from_translation(DVec3::splat(f64::from(k)))));
        }
        let camera = Camera {
            position: DVec3::ZERO,
            look_at: DVec3::Z,
            up: DVec3::Y,
        };
        let scene = b.finish(Vec::new(), Vec3::ZERO, Vec3::ZERO, camera);
        let names: Vec<(String, String)> = scene
            .objects_of(&[0, 1, 2, 3, 4, 5, 6, 7, crate::shared::NO_HIT])
            .into_iter()
            .map(|o| match scene.objects.get(o as usize) {
                Some(o) => (o.name.clone(), o.class.clone()),
                None => (String::new(), String::new()),
            })
            .collect();
        let pair = |n: &str, c: &str| (n.to_string(), c.to_string());
        let wanted = [
            pair("red", "red"),
            pair("red", "red"),
            pair("chair", "furniture"),
            pair("chair", "furniture"),
            pair("cup", "tableware"),
            pair("cup", "tableware"),
            pair("cup 1", "tableware"),
            pair("cup 1", "tableware"),
            pair("", ""),
        ];
        assert_eq!(names, wanted);
        let (classes, _) = scene.classes();
        assert_eq!(classes, ["furniture", "tableware", "red"].map(String::from));
    }
}
