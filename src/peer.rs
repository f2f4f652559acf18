//! Embree 3 (Intel's CPU ray tracing kernels, through the `embree` crate and the system's
//! `libembree3`) as the peer the traversal is measured against: it casts the very rays
//! [`crate::trace::cast::RayCast`] casts, into the same f32 triangles (the scene flattened,
//! camera-relative, rounded once), with its single-ray API on every core or its 8-wide packet
//! API, and answers in the same [`CastHit`]s (a hit's triangle is the scene triangle, as ids
//! name it).

use cgmath::{Vector3, Vector4};
use embree::sys;
use glam::{DVec3, Vec3};

use crate::error::{Error, Result};
use crate::scene::{MAX_FLATTENED, Scene};
pub use crate::trace::cast::light;
use crate::trace::cast::{CastHit, CastRay, NO_HIT};

/// A scene committed to Embree (its default build quality), with the corners it was given.
pub struct Embree<'a> {
    scene: embree::CommittedScene<'a>,
    /// The same scene's handle, for the packet calls the crate does not wrap.
    handle: Handle,
    /// Each scene triangle's corners, camera-relative, as Embree has them.
    corners: Vec<[Vec3; 3]>,
    /// How much the process's resident memory grew while Embree built its BVH (the commit;
    /// the vertex and index buffers were filled before), where Linux's `/proc` tells.
    pub build_resident: Option<u64>,
}

/// This process's resident memory in bytes (`VmRSS` of `/proc/self/status`), where there is
/// one.
fn resident() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// A committed scene's handle. Embree documents queries on a committed scene as safe from any
/// number of threads at once.
struct Handle(sys::RTCScene);

// SAFETY: only queries (rtcIntersect8) go through the handle, on a committed scene that
// outlives every use; Embree allows concurrent queries.
unsafe impl Sync for Handle {}
unsafe impl Send for Handle {}

/// Builds `scene` in Embree (timed: the returned seconds) and hands it to `work`.
pub fn with_embree<R>(scene: &Scene, work: impl FnOnce(&Embree, f64) -> R) -> Result<R> {
    let flat = scene.flattened(MAX_FLATTENED)?;
    let origin = flat.camera.position;
    let device = embree::Device::new();
    let count = flat.triangles.len();
    if count == 0 {
        return Err(Error::Scene("Embree needs at least one triangle".into()));
    }
    let corners: Vec<[Vec3; 3]> = flat
        .triangles
        .iter()
        .map(|t| t.map(|p| (p - origin).as_vec3()))
        .collect();
    let started = std::time::Instant::now();
    let mut mesh = embree::TriangleMesh::unanimated(&device, count, 3 * count);
    {
        let mut vertices = mesh.vertex_buffer.map();
        for (i, t) in corners.iter().enumerate() {
            for (k, p) in t.iter().enumerate() {
                vertices[3 * i + k] = Vector4::new(p.x, p.y, p.z, 0.0);
            }
        }
    }
    {
        let mut indices = mesh.index_buffer.map();
        for i in 0..count {
            let first = 3 * i as u32;
            indices[i] = Vector3::new(first, first + 1, first + 2);
        }
    }
    let mut geometry = embree::Geometry::Triangle(mesh);
    geometry.commit();
    let mut built = embree::Scene::new(&device);
    built.attach_geometry(geometry);
    // SAFETY: the handle is only read, while `built` lives.
    let handle = Handle(unsafe { built.handle() });
    let before = resident();
    let committed = built.commit();
    let seconds = started.elapsed().as_secs_f64();
    let build_resident = before
        .zip(resident())
        .map(|(before, after)| after.saturating_sub(before));
    let embree = Embree {
        scene: committed,
        handle,
        corners,
        build_resident,
    };
    Ok(work(&embree, seconds))
}

/// `rays` split over `threads` threads, each mapping its share with `each` into answers that
/// start as `blank`.
fn parallel<T: Send + Clone>(
    rays: &[CastRay],
    threads: usize,
    blank: T,
    each: impl Fn(&[CastRay], &mut [T]) + Sync,
) -> Vec<T> {
    let mut out = vec![blank; rays.len()];
    let chunk = rays.len().div_ceil(threads.max(1)).max(1);
    std::thread::scope(|s| {
        for (input, output) in rays.chunks(chunk).zip(out.chunks_mut(chunk)) {
            let each = &each;
            s.spawn(move || each(input, output));
        }
    });
    out
}

fn single(ray: &CastRay) -> sys::RTCRay {
    sys::RTCRay {
        org_x: ray.origin[0],
        org_y: ray.origin[1],
        org_z: ray.origin[2],
        tnear: ray.tmin,
        dir_x: ray.dir[0],
        dir_y: ray.dir[1],
        dir_z: ray.dir[2],
        time: 0.0,
        tfar: ray.tmax,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

fn missed() -> CastHit {
    CastHit {
        t: f32::INFINITY,
        triangle: NO_HIT,
        uv: [0.0; 2],
    }
}

impl Embree<'_> {
    /// The closest hits with `rtcIntersect1`, on `threads` threads.
    pub fn intersect1(&self, rays: &[CastRay], threads: usize) -> Vec<CastHit> {
        parallel(rays, threads, missed(), |input, output| {
            let mut context = embree::IntersectContext::incoherent();
            for (ray, out) in input.iter().zip(output) {
                let mut hit = embree::RayHit::new(single(ray));
                self.scene.intersect(&mut context, &mut hit);
                *out = if hit.hit.hit() {
                    CastHit {
                        t: hit.ray.tfar,
                        triangle: hit.hit.primID,
                        uv: [hit.hit.u, hit.hit.v],
                    }
                } else {
                    CastHit {
                        t: ray.tmax,
                        ..missed()
                    }
                };
            }
        })
    }

    /// Whether anything is hit, with `rtcOccluded1`, on `threads` threads.
    pub fn occluded1(&self, rays: &[CastRay], threads: usize) -> Vec<bool> {
        parallel(rays, threads, false, |input, output| {
            let mut context = embree::IntersectContext::incoherent();
            for (ray, out) in input.iter().zip(output) {
                let mut r = single(ray);
                self.scene.occluded(&mut context, &mut r);
                // Embree marks an occluded ray by setting tfar to -inf.
                *out = r.tfar == f32::NEG_INFINITY;
            }
        })
    }

    /// The closest hits with `rtcIntersect8` (packets of 8 consecutive rays, a coherent
    /// context), on `threads` threads.
    pub fn intersect8(&self, rays: &[CastRay], threads: usize) -> Vec<CastHit> {
        parallel(rays, threads, missed(), |input, output| {
            let mut context = embree::IntersectContext::coherent();
            for (batch, out) in input.chunks(8).zip(output.chunks_mut(8)) {
                let mut packet = packet8(batch);
                let valid = valid8(batch.len());
                // SAFETY: the packet and mask are 8 wide and 32-byte aligned as rtcIntersect8
                // reads them, the scene is committed and outlives the call.
                unsafe {
                    sys::rtcIntersect8(valid.0.as_ptr(), self.handle.0, &mut context, &mut *packet);
                }
                for (k, o) in out.iter_mut().enumerate() {
                    *o = if packet.hit.geomID[k] != u32::MAX {
                        CastHit {
                            t: packet.ray.tfar[k],
                            triangle: packet.hit.primID[k],
                            uv: [packet.hit.u[k], packet.hit.v[k]],
                        }
                    } else {
                        CastHit {
                            t: batch[k].tmax,
                            ..missed()
                        }
                    };
                }
            }
        })
    }
}

/// An 8-wide packet's lane mask, aligned to 32 bytes as Embree reads it.
#[repr(C, align(32))]
struct Valid8([i32; 8]);

/// Lanes `0..len` of an 8-wide packet are active (-1), the rest not (0).
fn valid8(len: usize) -> Valid8 {
    Valid8(std::array::from_fn(|k| if k < len { -1 } else { 0 }))
}

/// Up to 8 rays as one SoA packet (boxed: Embree wants it 32-byte aligned, as the type is).
fn packet8(batch: &[CastRay]) -> Box<sys::RTCRayHit8> {
    let lane = |k: usize, f: fn(&CastRay) -> f32| batch.get(k).map_or(0.0, f);
    let lanes = |f: fn(&CastRay) -> f32| -> [f32; 8] { std::array::from_fn(|k| lane(k, f)) };
    Box::new(sys::RTCRayHit8 {
        ray: sys::RTCRay8 {
            org_x: lanes(|r| r.origin[0]),
            org_y: lanes(|r| r.origin[1]),
            org_z: lanes(|r| r.origin[2]),
            tnear: lanes(|r| r.tmin),
            dir_x: lanes(|r| r.dir[0]),
            dir_y: lanes(|r| r.dir[1]),
            dir_z: lanes(|r| r.dir[2]),
            time: [0.0; 8],
            tfar: lanes(|r| r.tmax),
            mask: [u32::MAX; 8],
            id: [0; 8],
            flags: [0; 8],
        },
        hit: sys::RTCHit8 {
            Ng_x: [0.0; 8],
            Ng_y: [0.0; 8],
            Ng_z: [0.0; 8],
            u: [0.0; 8],
            v: [0.0; 8],
            primID: [u32::MAX; 8],
            geomID: [u32::MAX; 8],
            instID: [[u32::MAX; 8]; 1],
        },
    })
}

/// The rays of the peer benchmark, the same for both tracers: a lens's primary rays from the
/// eye; from each primary hit (Embree's), a shadow ray to `light` (camera-relative) and one
/// diffuse bounce (cosine-distributed about the face's normal, towards the eye's side, from a
/// per-ray hash), both leaving the surface by 1e-4 of the hit's distance from the eye.
pub struct Workload {
    /// From the eye, through each pixel the lens covers.
    pub primary: Vec<CastRay>,
    /// From each primary hit to the light (any hit within (0, 1] of the direction).
    pub shadow: Vec<CastRay>,
    /// From each primary hit, one diffuse bounce.
    pub bounce: Vec<CastRay>,
}

impl Workload {
    /// The rays for camera-space unit `directions` turned by `rotation` into the world.
    pub fn new(
        embree: &Embree,
        directions: &[DVec3],
        rotation: glam::DMat3,
        light: Vec3,
        threads: usize,
    ) -> Self {
        let primary: Vec<CastRay> = directions
            .iter()
            .map(|d| CastRay {
                origin: [0.0; 3],
                tmin: 0.0,
                dir: (rotation * *d).as_vec3().to_array(),
                tmax: f32::MAX,
            })
            .collect();
        let hits = embree.intersect1(&primary, threads);
        let (mut shadow, mut bounce) = (Vec::new(), Vec::new());
        for (k, (ray, hit)) in primary.iter().zip(&hits).enumerate() {
            if hit.triangle == NO_HIT {
                continue;
            }
            let dir = Vec3::from(ray.dir);
            let [a, b, c] = embree.corners[hit.triangle as usize];
            let mut n = (b - a).cross(c - a).normalize();
            if n.dot(dir) > 0.0 {
                n = -n;
            }
            let p = dir * hit.t;
            let origin = p + n * (1e-4 * hit.t);
            shadow.push(CastRay {
                origin: origin.to_array(),
                tmin: 0.0,
                dir: (light - origin).to_array(),
                tmax: 1.0,
            });
            // Cosine-distributed about n (Malley's method) from two hashed uniforms.
            let (u1, u2) = (unit(k as u64, 1), unit(k as u64, 2));
            let (r, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
            let (t1, t2) = n.any_orthonormal_pair();
            let d = t1 * (r * phi.cos()) + t2 * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt();
            bounce.push(CastRay {
                origin: origin.to_array(),
                tmin: 0.0,
                dir: d.to_array(),
                tmax: f32::MAX,
            });
        }
        Self {
            primary,
            shadow,
            bounce,
        }
    }
}

/// A uniform number in [0, 1) from `(index, k)` (SplitMix64's finaliser).
fn unit(index: u64, k: u64) -> f32 {
    let mut x = index.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ k.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^= x >> 31;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

/// How far two tracers' answers to the same rays agree.
#[derive(Clone, Copy, Debug)]
pub struct Agreement {
    /// Rays both hit or both miss, as a share.
    pub hit_or_miss: f64,
    /// Rays whose hit is the same triangle (or both miss), as a share.
    pub triangle: f64,
    /// The largest relative difference of distance where the triangle is the same.
    pub distance: f64,
}

impl Agreement {
    /// Compares closest hits.
    pub fn of(a: &[CastHit], b: &[CastHit]) -> Self {
        assert_eq!(a.len(), b.len());
        let n = a.len().max(1) as f64;
        let (mut both, mut same, mut distance) = (0, 0, 0.0f64);
        for (x, y) in a.iter().zip(b) {
            both += usize::from((x.triangle == NO_HIT) == (y.triangle == NO_HIT));
            if x.triangle == y.triangle {
                same += 1;
                if x.triangle != NO_HIT {
                    let (s, t) = (f64::from(x.t), f64::from(y.t));
                    distance = distance.max((s - t).abs() / t.abs().max(f64::MIN_POSITIVE));
                }
            }
        }
        Self {
            hit_or_miss: both as f64 / n,
            triangle: same as f64 / n,
            distance,
        }
    }

    /// Compares any-hit answers (occluded or not): only `hit_or_miss` means anything.
    pub fn of_occlusion(a: &[bool], b: &[bool]) -> Self {
        assert_eq!(a.len(), b.len());
        let same = a.iter().zip(b).filter(|(x, y)| x == y).count();
        let share = same as f64 / a.len().max(1) as f64;
        Self {
            hit_or_miss: share,
            triangle: share,
            distance: 0.0,
        }
    }
}
