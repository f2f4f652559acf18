//! The cube-map path with ray-traced faces: face/UV selection on the GPU against its CPU twin
//! over every hard case, the sampler against its CPU twin on the same faces, the
//! faces a lens needs, and the resampling error against the direct render as faces grow.

mod common;

use common::{camera, ctx};
use fisheye_rt::cube::{
    Coverage, CubeMap, CubeMethod, CubeSettings, FACES, MOST_TAPS, face_uv, face_uv_gpu, resample,
    texels_across,
};
use fisheye_rt::scene::builtin;
use fisheye_rt::trace::{GpuScene, RenderOptions, TracePass, linear_to_srgb};
use glam::{DVec2, Vec3};

/// Directions that stress the selection: a dense Fibonacci sphere, the axes, face edges and
/// cube corners exactly and one ulp either side, exact ties, and signed zeros.
fn hard_directions() -> Vec<Vec3> {
    let mut dirs = Vec::new();
    let n = 20_000;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    for i in 0..n {
        let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - y * y).sqrt();
        let phi = golden * i as f64;
        dirs.push(glam::DVec3::new(r * phi.cos(), y, r * phi.sin()).as_vec3());
    }
    let values = [-1.0f32, -0.0, 0.0, 1.0];
    for x in values {
        for y in values {
            for z in values {
                dirs.push(Vec3::new(x, y, z));
            }
        }
    }
    let next = |v: f32, up: bool| {
        let b = v.to_bits();
        f32::from_bits(if (v > 0.0) == up { b + 1 } else { b - 1 })
    };
    for d in dirs
        .clone()
        .into_iter()
        .skip(n)
        .filter(|d| d.length_squared() > 0.0)
    {
        for k in 0..3 {
            for up in [false, true] {
                let mut e = d;
                if e[k] != 0.0 {
                    e[k] = next(e[k], up);
                    dirs.push(e);
                }
            }
        }
    }
    dirs
}

#[test]
fn gpu_picks_the_same_face_and_uv_as_the_cpu() {
    let dirs = hard_directions();
    let gpu = face_uv_gpu(ctx(), &dirs).unwrap();
    let mut worst = 0.0f32;
    for (d, (face, uv)) in dirs.iter().zip(&gpu) {
        let (cpu_face, cpu_uv) = face_uv(*d);
        assert_eq!(*face, cpu_face, "face of {d:?}");
        // Vulkan lets a division be off by 2.5 ulp; the quotient is in [-1, 1], then halved.
        let e = (*uv - cpu_uv).abs().max_element();
        assert!(e <= 3e-7, "uv of {d:?}: gpu {uv} cpu {cpu_uv}");
        assert!(
            (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y),
            "{d:?}: {uv}"
        );
        worst = worst.max(e);
    }
    eprintln!("{} directions, largest uv difference {worst:e}", dirs.len());
}

/// Faces the lens cannot reach are never rendered, and of the others only the part sampling
/// reads: the image is bit for bit the one rendered from whole faces.
#[test]
fn only_the_reachable_parts_of_faces_are_rendered() {
    let scene = builtin::scene("default").unwrap();
    let gpu_scene = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
    let cam = camera("equidistant:f=0.45,fov=180", 64, 48);
    let new = |cam: &fisheye_rt::lens::LensCamera, size, coverage| {
        let settings = CubeSettings {
            coverage,
            ..CubeSettings::new(size, CubeMethod::Traced)
        };
        CubeMap::new(ctx(), cam, &gpu_scene, &settings)
    };
    let names = |cube: &CubeMap| -> Vec<&str> {
        FACES
            .iter()
            .zip(cube.regions())
            .filter_map(|(f, r)| r.map(|_| f.name))
            .collect()
    };
    let parts = new(&cam, 32, Coverage::Reachable).unwrap();
    let whole = new(&cam, 32, Coverage::WholeFaces).unwrap();
    assert_eq!(names(&parts), ["+x", "-x", "+y", "-y", "+z"]);
    let traced = |c: &CubeMap| {
        c.regions()
            .iter()
            .flatten()
            .map(|r| r.texels())
            .sum::<u64>()
    };
    // A 180° lens reaches the front face and the front half of each side face.
    let share = traced(&parts) as f64 / traced(&whole) as f64;
    assert!(share < 0.65, "traced {share} of the whole faces");
    let a = parts.render(ctx(), &gpu_scene, &scene.camera).unwrap();
    let b = whole.render(ctx(), &gpu_scene, &scene.camera).unwrap();
    let bits = |c: &[[f32; 4]]| c.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a), bits(&b));

    // Faces finer than the pixels: the resampler reads a grid of lookups across each pixel,
    // whose rim pixels reach past the centres' directions.
    let fine = |coverage| {
        let cube = new(&cam, 128, coverage).unwrap();
        cube.render(ctx(), &gpu_scene, &scene.camera).unwrap()
    };
    assert_eq!(
        bits(&fine(Coverage::Reachable)),
        bits(&fine(Coverage::WholeFaces))
    );

    let narrow = new(&camera("rectilinear:f=2", 64, 48), 16, Coverage::Reachable).unwrap();
    assert_eq!(names(&narrow), ["+z"]);
    let message = new(&cam, 0, Coverage::Reachable).err().unwrap().to_string();
    assert!(message.contains("cube face size 0"), "{message}");
}

/// Resampling a ray-traced cube against tracing the fisheye directly with 64 rays a pixel, on
/// the default room, its textures on: the sampler equals the CPU's twin (`resample`: the
/// faces' bilinear reconstruction averaged over the pixel's square), and the error (MSE of
/// the displayed, sRGB-encoded values) falls at every doubling of the face size and, while
/// the face texels are larger than the pixels, is larger where they are larger. With one
/// lookup a pixel it rose again once face texels were finer than the pixels (measured then,
/// textures on: 128 and 256 texels each about twice 64's): a point sample of a finer image
/// aliases it.
#[test]
fn cube_error_falls_as_faces_grow() {
    let scene = builtin::scene("default").unwrap();
    let options = RenderOptions::default();
    let gpu_scene = GpuScene::new(ctx(), &scene, &options).unwrap();
    let cam = camera("canon-8-15mm@8mm", 128, 96);
    let direct_pass =
        TracePass::supersampled(ctx(), &cam, &gpu_scene, options.directions, 64).unwrap();
    let mut encoder = ctx().device.create_command_encoder(&Default::default());
    direct_pass.encode(&mut encoder, &gpu_scene, None);
    ctx().queue.submit([encoder.finish()]);
    let direct = direct_pass.read(ctx()).unwrap();
    let directions = cam.directions();
    let mut errors = Vec::new();
    let mut concentration = Vec::new();
    let mut most_taps = 0;
    for size in [16, 32, 64, 128, 256] {
        let settings = CubeSettings::new(size, CubeMethod::Traced);
        let cube = CubeMap::new(ctx(), &cam, &gpu_scene, &settings).unwrap();
        let colour = cube.render(ctx(), &gpu_scene, &scene.camera).unwrap();
        let texels = cube.texels(ctx()).unwrap();
        let (mut sum, mut count, mut near_half) = (0.0f64, 0, 0);
        // Per pixel: the cube's texel size there (relative to a face centre's) and the error.
        let mut by_texel = Vec::new();
        for (i, c) in colour.iter().enumerate() {
            // The cube's mask is its centre ray's (the direct render's rim pixels have some
            // samples in the circle).
            let Some(d) = directions[i] else {
                assert_eq!(c[3], 0.0, "pixel {i} is masked");
                continue;
            };
            assert_eq!(c[3], 1.0, "pixel {i} has a ray");
            let width = cam.size.width as usize;
            let (x, y) = ((i % width) as f64 + 0.5, (i / width) as f64 + 0.5);
            let steps = cam.steps(DVec2::new(x, y), d, 1.0).map(|s| s.as_vec3());
            let d = d.as_vec3();
            let (face, uv) = face_uv(d);
            let across = texels_across(size, face, d, steps);
            most_taps = most_taps.max((across.round() as u32).clamp(1, MOST_TAPS));
            // The GPU's f32 steps differ from these f64 ones by about 1e-6 of their length:
            // where the texels across lie that near a half, the two may round to different
            // grids.
            if (across.fract() - 0.5).abs() < 1e-4 {
                near_half += 1;
                continue;
            }
            let expected = resample(&texels, size, d, steps);
            // A texel at face coordinates (a, b) subtends (1 + a² + b²)^(-3/4) of the angle of
            // one at the centre: the cube resolves least at face centres.
            let ab = uv * 2.0 - 1.0;
            let texel_angle = f64::from(1.0 + ab.length_squared()).powf(-0.75);
            let mut pixel_error = 0.0;
            for k in 0..3 {
                // Bilinear lookup is continuous: f32 and f64 directions (1e-7 rad apart) give
                // nearly the same sample.
                assert!(
                    (c[k] - expected[k]).abs() < 1e-3,
                    "pixel {i}: {c:?} vs {expected:?}"
                );
                // Error as the image shows it: clamped and sRGB-encoded, in [0, 1].
                let shown = |x: f32| f64::from(linear_to_srgb(x.clamp(0.0, 1.0)));
                let e = shown(c[k]) - shown(direct.colour[i][k]);
                sum += e * e;
                pixel_error += e * e / 3.0;
            }
            count += 3;
            by_texel.push((texel_angle, pixel_error));
        }
        assert!(
            near_half * 1000 < count,
            "{near_half} pixels near a half texel"
        );
        let mse = sum / f64::from(count);
        by_texel.sort_by(|a, b| a.0.total_cmp(&b.0));
        let half = by_texel.len() / 2;
        let mean = |p: &[(f64, f64)]| p.iter().map(|p| p.1).sum::<f64>() / p.len() as f64;
        let (fine, coarse) = (mean(&by_texel[..half]), mean(&by_texel[half..]));
        eprintln!(
            "cube face {size}: MSE against direct RT {mse:.3e}; where texels are largest \
             {coarse:.3e}, smallest {fine:.3e}"
        );
        errors.push(mse);
        concentration.push(coarse / fine);
    }
    eprintln!("MSE, larger-texel half / smaller-texel half of the pixels: {concentration:.2?}");
    // The largest faces take several lookups a pixel somewhere (else this tests one lookup).
    assert!(most_taps >= 3, "{most_taps}");
    // Measured on lavapipe: 7.65e-3, 2.73e-3, 8.41e-4, 1.26e-4, 2.62e-5: 16 → 256 gains about
    // 290×. With one lookup a pixel (MOST_TAPS = 1) the same faces gave 8.16e-4 at 64, then
    // 1.02e-3 and 2.42e-3. The bounds leave a factor of 8 and more for other drivers.
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "{errors:?}");
    assert!(errors[0] / errors[4] > 40.0, "{errors:?}");
    assert!(errors[4] < 2e-4, "{errors:?}");
    // Where the cube resolves least (the half of the pixels on the largest texels, towards
    // face centres), the error is larger while face texels are larger than the pixels (16 and
    // 32 texels: 5.6° and 2.8° at a face's centre, the pixels about 1.4°). Measured: 1.15 and
    // 1.34 times the other half's.
    assert!(
        concentration[..2].iter().all(|&r| r > 1.0),
        "{concentration:?}"
    );
}

/// The faces live in a texture array, so a cube larger than one storage binding renders: a
/// narrow lens (the front face alone) through faces just past the binding limit, against the
/// direct render.
#[test]
fn faces_larger_than_a_storage_binding_render() {
    let limits = ctx().device.limits();
    let past_binding = ((limits.max_storage_buffer_binding_size / 96) as f64).sqrt() as u32;
    let size = (past_binding + 1).min(limits.max_texture_dimension_2d - 2);
    let scene = builtin::scene("default").unwrap();
    let options = RenderOptions::default();
    let gpu_scene = GpuScene::new(ctx(), &scene, &options).unwrap();
    let cam = camera("rectilinear:f=2", 64, 48);
    let settings = CubeSettings::new(size, CubeMethod::Traced);
    let cube = CubeMap::new(ctx(), &cam, &gpu_scene, &settings).unwrap();
    let colour = cube.render(ctx(), &gpu_scene, &scene.camera).unwrap();
    let direct = fisheye_rt::trace::render(ctx(), &scene, &cam, &options).unwrap();
    let mse = colour
        .iter()
        .zip(&direct.colour)
        .flat_map(|(a, b)| (0..3).map(move |k| f64::from(a[k].min(1.0) - b[k].min(1.0)).powi(2)))
        .sum::<f64>()
        / (3 * colour.len()) as f64;
    eprintln!("faces of {size}² texels: MSE against the direct render {mse:.2e}");
    // At 64×48 pixels the faces resolve far more than the image: only sub-pixel shifts of
    // edges remain.
    assert!(mse < 1e-3, "{mse}");
}

/// The border texels of traced faces are real samples of the neighbouring faces: inside a box
/// whose six walls have six colours, seen from its centre along the walls' axes, every inner
/// texel of a face shows that face's wall, and every border texel (a direction just past the
/// edge) shows the neighbour's wall, never a copy of its own face.
#[test]
fn border_texels_show_the_neighbouring_faces() {
    use fisheye_rt::scene::{Camera, Material, MeshBuilder};
    use glam::{DVec3, Vec2};
    // Camera space is world space: x right, y down, z forward.
    let walls = [
        (DVec3::X, Vec3::new(1.0, 0.0, 0.0)),
        (DVec3::NEG_X, Vec3::new(0.0, 1.0, 0.0)),
        (DVec3::Y, Vec3::new(0.0, 0.0, 1.0)),
        (DVec3::NEG_Y, Vec3::new(1.0, 1.0, 0.0)),
        (DVec3::Z, Vec3::new(0.0, 1.0, 1.0)),
        (DVec3::NEG_Z, Vec3::new(1.0, 0.0, 1.0)),
    ];
    let mut b = MeshBuilder::new();
    for (axis, colour) in walls {
        let m = b.material(Material::diffuse("wall", colour));
        // A 2 × 2 square at distance 1 along `axis`, spanned by the other two axes.
        let (u, v) = (
            DVec3::new(axis.y, axis.z, axis.x) * 2.0,
            DVec3::new(axis.z, axis.x, axis.y) * 2.0,
        );
        b.quad(axis - 0.5 * (u + v), u, v, glam::Vec2::ONE, m);
    }
    let pose = Camera {
        position: DVec3::ZERO,
        look_at: DVec3::Z,
        up: DVec3::NEG_Y,
    };
    let scene = b.finish(Vec::new(), Vec3::ZERO, Vec3::ONE, pose);
    let gpu_scene = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
    let size = 8;
    let settings = CubeSettings {
        coverage: Coverage::WholeFaces,
        ..CubeSettings::new(size, CubeMethod::Traced)
    };
    let all_round = camera("equidistant:f=0.2,fov=360", 32, 32);
    let cube = CubeMap::new(ctx(), &all_round, &gpu_scene, &settings).unwrap();
    cube.render(ctx(), &gpu_scene, &pose).unwrap();
    let texels = cube.texels(ctx()).unwrap();
    let side = size as usize + 2;
    let mut border = 0;
    for (f, face) in FACES.iter().enumerate() {
        for y in 0..side {
            for x in 0..side {
                let edge_x = x == 0 || x == side - 1;
                let edge_y = y == 0 || y == side - 1;
                if edge_x && edge_y {
                    continue; // a corner texel looks along the cube's corner: two walls tie
                }
                // The texel's centre in face coordinates, past ±1 in the border.
                let ab = (Vec2::new(x as f32, y as f32) - 0.5) / size as f32 * 2.0 - 1.0;
                let d = (face.right * ab.x + face.down * ab.y + face.forward).as_dvec3();
                let axis = d.abs().max_position();
                let wall = 2 * axis + usize::from(d[axis] < 0.0);
                assert_eq!(
                    wall != f,
                    edge_x || edge_y,
                    "face {} texel ({x}, {y})",
                    face.name
                );
                let shown = Vec3::from_slice(&texels[(f * side + y) * side + x][..3]);
                assert_eq!(
                    shown, walls[wall].1,
                    "face {} texel ({x}, {y}) looks along {d}: it shows {shown}",
                    face.name
                );
                border += usize::from(wall != f);
            }
        }
    }
    assert_eq!(border, 6 * 4 * size as usize);
}
