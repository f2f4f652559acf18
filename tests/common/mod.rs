//! Shared by the GPU tracer tests: one device, and the comparison of a GPU render with the
//! f64 reference under the tolerances stated here.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::{ImageSize, LensCamera, parse_spec};
use fisheye_rt::scene::Scene;
use fisheye_rt::trace::{NO_HIT, RenderOptions, RenderOutput, cpu::Reference, render};

/// The device of the calling test's thread. Each test thread holds its own while it runs and
/// hands it on when it ends, so as many devices exist as tests run at once (cargo's
/// `--test-threads`, the cores by default). One device for them all would serialize them:
/// lavapipe compiles a pipeline at its first dispatch, on the device's one queue thread, and
/// compiling is most of these tests' time (`adaptive_gpu` from an empty shader cache on a
/// 2-core AMD EPYC: 254 s with one device, using 1.2 of the 2 cores; 172 s with one a thread).
pub fn ctx() -> &'static GpuContext {
    static FREE: Mutex<Vec<&'static GpuContext>> = Mutex::new(Vec::new());
    struct Held(&'static GpuContext);
    impl Drop for Held {
        fn drop(&mut self) {
            FREE.lock().unwrap_or_else(|e| e.into_inner()).push(self.0);
        }
    }
    thread_local! {
        static HELD: Held = Held({
            let free = FREE.lock().unwrap_or_else(|e| e.into_inner()).pop();
            free.unwrap_or_else(|| {
                let made = GpuContext::new().expect("these tests need a GPU adapter (or lavapipe)");
                Box::leak(Box::new(made))
            })
        });
    }
    HELD.with(|held| held.0)
}

pub fn camera(spec: &str, w: u32, h: u32) -> LensCamera {
    LensCamera::new(parse_spec(spec).unwrap(), ImageSize::new(w, h).unwrap())
}

/// Whether pixel `i` of an id image borders a different id (4-neighbourhood).
pub fn on_id_edge(ids: &[u32], size: ImageSize, i: usize) -> bool {
    let (w, h) = (size.width as usize, size.height as usize);
    let (x, y) = (i % w, i / w);
    let neighbours = [
        (x > 0).then(|| i - 1),
        (x + 1 < w).then(|| i + 1),
        (y > 0).then(|| i - w),
        (y + 1 < h).then(|| i + w),
    ];
    neighbours.into_iter().flatten().any(|j| ids[j] != ids[i])
}

/// How far a GPU render may be from the f64 reference. The README's accuracy section
/// ("Tested against an f64 reference tracer") quotes these figures; each constant below says
/// what it covers and why it is what it is. Pixels whose primary ids differ are not compared
/// for distance, normal or colour, so their number is bounded too, and each must lie on an
/// edge of the *reference's* id image (a wrong pixel of the GPU's own cannot excuse itself).
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    /// Most pixels whose primary triangle differs from the reference's on an edge of the
    /// reference's id image.
    pub id_mismatches: usize,
    /// Largest relative difference of the primary hit's distance.
    pub distance: f64,
    /// Largest angle between the GPU's and the reference's shading normals, in radians.
    pub normal: f64,
    /// Largest mean (over compared pixels) of the per-pixel colour difference (largest
    /// channel, linear radiance; relative above 1, see [`colour_error`]).
    pub mean_colour: f64,
    /// Most pixels whose colour differs by more than [`OUTLIER`] in some channel.
    pub colour_outliers: usize,
}

/// A colour difference beyond this (any channel, see [`colour_error`]) is an outlier.
pub const OUTLIER: f64 = 0.02;

/// Built-in and synthetic scenes. The GPU's rays differ from the reference's by about 1e-7 rad
/// (`tests/lens_gpu.rs`) over the same f32 geometry, and both give exact ties to the lower
/// triangle, so no primary hit changes triangle here: measured none, asserted none.
/// Distances then agree to f32 rounding of the hit, amplified at grazing incidence: measured
/// at most 8.6e-6 (many-small), asserted 1e-5. Flat normals are f32 cross products (measured
/// ≤ 1e-7 rad); interpolated normals also carry the barycentrics' error, which a grazing hit
/// on a coarse sphere amplifies: measured at most 1.8e-5 rad (the default room), asserted
/// 5e-5. Colours: measured mean at most 1.1e-5 (TUM-VI's lens on the default room), asserted
/// 2e-5, and no pixel off by more than [`OUTLIER`] (shadow and reflection rays start from hits
/// that agree to that precision too).
pub const SYNTHETIC: Tolerance = Tolerance {
    id_mismatches: 0,
    distance: 1e-5,
    normal: 5e-5,
    mean_colour: 2e-5,
    colour_outliers: 0,
};

/// The shipped scene files and the OBJ Cornell spheres (at 64×48 and 128×96), and ray queries
/// (whose driver decides edges and ties by its own triangle test). Real meshes have
/// silhouettes seen edge-on, so a few primary ids differ on edges (measured: 8 of 3,072 on
/// Sibenik), asserted at most 0.5% of the pixels. A shadow or reflection ray that grazes a
/// silhouette may change triangle just as a primary ray does, and then its pixel's colour
/// jumps: measured at most 1 such pixel per image (a shadow edge in the Cornell box, the
/// bunny's mirror ball, a sphere's silhouette by ray query), asserted at most 0.1% of the
/// pixels. The mean includes them: measured at most 1.5e-4, asserted 3e-4. Distances and
/// normals as [`SYNTHETIC`].
pub fn real_scene(pixels: usize) -> Tolerance {
    Tolerance {
        id_mismatches: pixels / 200,
        mean_colour: 3e-4,
        colour_outliers: pixels / 1000,
        ..SYNTHETIC
    }
}

/// The difference of a colour channel from the reference's: absolute up to 1 (the displayed
/// range), relative above (a lamp seen directly has radiance 100 and more, held to f32's
/// relative precision like any other value).
fn colour_error(gpu: f32, reference: f32) -> f64 {
    f64::from((gpu - reference).abs()) / f64::from(reference.abs()).max(1.0)
}

/// The angle between two unit vectors, accurate for tiny angles.
fn angle(a: [f32; 4], b: [f32; 4]) -> f64 {
    let a = glam::DVec3::new(a[0].into(), a[1].into(), a[2].into());
    let b = glam::DVec3::new(b[0].into(), b[1].into(), b[2].into());
    a.cross(b).length().atan2(a.dot(b))
}

/// Compares a GPU render with the reference under `tolerance`: masks and finiteness everywhere;
/// ids (differences only on the reference's id edges); then, where ids agree, distances,
/// normals and colours. Returns the mean colour error.
pub fn assert_agrees(
    name: &str,
    gpu: &RenderOutput,
    cpu: &RenderOutput,
    tolerance: Tolerance,
) -> f64 {
    let n = gpu.ids.len();
    let mut mismatches = 0;
    let (mut distance, mut normal) = (0.0f64, 0.0f64);
    let mut colour_sum = 0.0;
    let mut outliers = 0;
    let mut compared = 0;
    for i in 0..n {
        assert_eq!(gpu.valid(i), cpu.valid(i), "{name}: masks differ at {i}");
        assert!(
            gpu.colour[i].iter().all(|c| c.is_finite()),
            "{name}: non-finite colour at {i}"
        );
        if gpu.ids[i] != cpu.ids[i] {
            assert!(
                on_id_edge(&cpu.ids, cpu.size, i),
                "{name}: ids differ inside a surface of the reference at pixel {i}: gpu {} cpu {}",
                gpu.ids[i],
                cpu.ids[i]
            );
            mismatches += 1;
            continue;
        }
        if !gpu.valid(i) {
            continue;
        }
        if gpu.ids[i] != NO_HIT {
            let (a, b) = (f64::from(gpu.geometry[i][3]), f64::from(cpu.geometry[i][3]));
            distance = distance.max((a - b).abs() / b);
            normal = normal.max(angle(gpu.geometry[i], cpu.geometry[i]));
        } else {
            assert_eq!(
                gpu.geometry[i], [0.0; 4],
                "{name}: a miss has geometry at {i}"
            );
        }
        let e = (0..3)
            .map(|k| colour_error(gpu.colour[i][k], cpu.colour[i][k]))
            .fold(0.0, f64::max);
        colour_sum += e;
        compared += 1;
        if e > OUTLIER {
            outliers += 1;
        }
    }
    let mean = colour_sum / compared.max(1) as f64;
    eprintln!(
        "{name}: {mismatches}/{n} ids differ (on edges), distance {distance:.1e}, normal \
         {normal:.1e} rad, colour mean {mean:.1e}, {outliers} outliers"
    );
    assert!(
        mismatches <= tolerance.id_mismatches,
        "{name}: {mismatches} ids differ, {} allowed",
        tolerance.id_mismatches
    );
    assert!(
        distance <= tolerance.distance,
        "{name}: distances differ by {distance:e} relative, {:e} allowed",
        tolerance.distance
    );
    assert!(
        normal <= tolerance.normal,
        "{name}: normals differ by {normal:e} rad, {:e} allowed",
        tolerance.normal
    );
    assert!(
        mean <= tolerance.mean_colour,
        "{name}: mean colour error {mean:e}, {:e} allowed",
        tolerance.mean_colour
    );
    assert!(
        outliers <= tolerance.colour_outliers,
        "{name}: {outliers} pixels off by more than {OUTLIER}, {} allowed",
        tolerance.colour_outliers
    );
    mean
}

/// A scene as the command line names it (`builtin:NAME`, or a file relative to the
/// repository); a failure names the file and what is wrong with it.
pub fn scene(spec: &str) -> Scene {
    let path = if spec.starts_with("builtin:") {
        spec.to_string()
    } else {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join(spec);
        assert!(file.exists(), "{} is missing", file.display());
        file.to_string_lossy().into_owned()
    };
    fisheye_rt::scene::load(&path)
        .unwrap_or_else(|e| panic!("{spec}: {e}"))
        .scene
}

/// A file of the third-party scenes in `scenes/`; a clear failure if it is not there.
pub fn shared(path: &str) -> PathBuf {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(path);
    assert!(
        file.exists(),
        "{} is missing: the third-party scenes ship in scenes/ (see scenes/README.md)",
        file.display()
    );
    file
}

/// Asserts that every pixel whose primary ray hit shows `expected` to within `tolerance` (per
/// channel); returns how many hit.
pub fn assert_every_hit_is(
    out: &RenderOutput,
    expected: glam::Vec3,
    tolerance: f32,
    what: &str,
) -> usize {
    let mut hits = 0;
    for (i, id) in out.ids.iter().enumerate() {
        if *id == NO_HIT {
            continue;
        }
        hits += 1;
        let c = glam::Vec3::from_slice(&out.colour[i][..3]);
        assert!(
            (c - expected).abs().max_element() <= tolerance,
            "{what}: pixel {i} shows {c}, not {expected}"
        );
    }
    hits
}

pub fn both(scene: &Scene, cam: &LensCamera) -> (RenderOutput, RenderOutput) {
    let options = RenderOptions::default();
    let gpu = render(ctx(), scene, cam, &options).unwrap();
    let cpu = Reference::new(scene, options.max_depth).render(cam);
    (gpu, cpu)
}
