//! Adaptive sampling (`trace::AdaptivePass`) against uniform sampling on the same device:
//! exactly uniform at threshold 0, exact ground truth, rays where the image has edges and
//! none of their own where it is smooth, the same image on every run, and error that falls
//! as the threshold does.

#[path = "../common/mod.rs"]
mod common;
mod glass;
mod planes;

use common::{camera, ctx, scene};
use fisheye_rt::compare::image_error;
use fisheye_rt::lens::LensCamera;
use fisheye_rt::lens::gpu::DirectionSource;
use fisheye_rt::scene::Scene;
use fisheye_rt::shared::ADAPTIVE_BLOCK;
use fisheye_rt::trace::{
    Adaptive, AdaptivePass, GpuScene, NO_HIT, RenderOptions, RenderOutput, SampleLanes, Stage,
    TracePass, linear_to_srgb,
};

fn uniform(gpu: &GpuScene, cam: &LensCamera, spp: u32) -> RenderOutput {
    let options = RenderOptions::default();
    TracePass::supersampled(ctx(), cam, gpu, options.directions, spp)
        .unwrap()
        .trace(ctx(), gpu, "uniform")
        .unwrap()
}

/// An adaptive frame at `threshold` with at most `spp` samples a pixel: its outputs and the
/// rays each pixel's colour took.
fn adaptive(
    gpu: &GpuScene,
    cam: &LensCamera,
    spp: u32,
    threshold: f32,
    ground_truth: bool,
) -> (RenderOutput, Vec<u32>) {
    let (out, rays, _) = adaptive_stages(gpu, cam, spp, threshold, ground_truth);
    (out, rays)
}

/// As [`adaptive`], with the rays each stage traced.
fn adaptive_stages(
    gpu: &GpuScene,
    cam: &LensCamera,
    spp: u32,
    threshold: f32,
    ground_truth: bool,
) -> (RenderOutput, Vec<u32>, Vec<(Stage, u64)>) {
    let lanes = SampleLanes::for_device(&ctx().device);
    adaptive_laid_out(gpu, cam, (spp, threshold, ground_truth), lanes)
}

/// As [`adaptive_stages`] (at `spp`, `threshold`, with or without the ground truth), each
/// pixel's samples spread over invocations as `lanes` says.
fn adaptive_laid_out(
    gpu: &GpuScene,
    cam: &LensCamera,
    (spp, threshold, ground_truth): (u32, f32, bool),
    lanes: SampleLanes,
) -> (RenderOutput, Vec<u32>, Vec<(Stage, u64)>) {
    let options = Adaptive {
        threshold,
        ground_truth,
        every_pixel: false,
    };
    adaptive_with(gpu, cam, spp, options, lanes)
}

/// An adaptive frame with `options` and at most `spp` samples a pixel, each pixel's samples
/// spread over invocations as `lanes` says: as [`adaptive_stages`] returns it.
fn adaptive_with(
    gpu: &GpuScene,
    cam: &LensCamera,
    spp: u32,
    options: Adaptive,
    lanes: SampleLanes,
) -> (RenderOutput, Vec<u32>, Vec<(Stage, u64)>) {
    let source = DirectionSource::Computed;
    let pass = AdaptivePass::with_lanes(ctx(), cam, gpu, source, spp, options, lanes).unwrap();
    let out = pass.trace(ctx(), gpu, "adaptive").unwrap();
    let stages = pass.read_stage_rays(ctx()).unwrap();
    (out, pass.read_rays(ctx()).unwrap(), stages)
}

fn upload(scene: &Scene) -> GpuScene {
    GpuScene::new(ctx(), scene, &RenderOptions::default()).unwrap()
}

/// At threshold 0 every block is refined and every pixel supersampled with the very samples
/// uniform sampling takes, summed in the same order: the same bits, in either layout of the
/// samples over invocations. Side by side (`SampleLanes::PerSample`), one invocation each up
/// to a workgroup's 64: 16 samples fill a workgroup with 4 pixels, 9 leave one invocation of
/// 64 idle, 256 take 4 rounds of 64; or an invocation a pixel (`PerPixel`).
#[test]
fn threshold_zero_is_uniform_sampling_exactly() {
    let room = scene("builtin:default");
    let cam = camera("canon-8-15mm@8mm", 61, 46);
    // Each layout on a thread of its own, with a device of its own (`ctx`): most of the time
    // is lavapipe compiling each layout's kernels, one core each.
    std::thread::scope(|scope| {
        for lanes in [SampleLanes::PerSample, SampleLanes::PerPixel] {
            let (room, cam) = (&room, &cam);
            scope.spawn(move || {
                let gpu = upload(room);
                for spp in [16, 9, 256] {
                    threshold_zero_at(&gpu, cam, spp, lanes);
                }
            });
        }
    });
}

fn threshold_zero_at(gpu: &GpuScene, cam: &LensCamera, spp: u32, lanes: SampleLanes) {
    let reference = uniform(gpu, cam, spp);
    let (out, rays, stages) = adaptive_laid_out(gpu, cam, (spp, 0.0, true), lanes);
    assert_eq!(
        out.colour, reference.colour,
        "colour at {spp} samples, {lanes:?}"
    );
    // Every lattice point; every other pixel but those of blocks wholly outside the lens
    // (filled as masked), so at least every one the lens covers; every pixel's 16 samples
    // (counted as rays where the lens masks them, though they cost a lens evaluation
    // alone); none interpolated.
    let (w, h) = (61u32, 46u32);
    let on_lattice = |x: u32, y: u32| {
        (x.is_multiple_of(ADAPTIVE_BLOCK) || x == w - 1)
            && (y.is_multiple_of(ADAPTIVE_BLOCK) || y == h - 1)
    };
    let lattice = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| on_lattice(x, y))
        .count() as u64;
    let pixels = u64::from(w * h);
    let centres = uniform(gpu, cam, 1);
    let covered_off_lattice = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| !on_lattice(x, y) && centres.valid((y * w + x) as usize))
        .count() as u64;
    let [coarse, midpoints, refine, supersample, truth] = stages[..] else {
        panic!("{stages:?}")
    };
    assert_eq!(coarse, (Stage::Coarse, lattice));
    assert_eq!((midpoints.0, refine.0), (Stage::Midpoints, Stage::Refine));
    // The midpoints and the half-blocks' other pixels, each listed once.
    let listed = midpoints.1 + refine.1;
    assert!(
        (covered_off_lattice..=pixels - lattice).contains(&listed),
        "{midpoints:?} {refine:?}: {covered_off_lattice} covered"
    );
    assert_eq!(supersample, (Stage::Supersample, u64::from(spp) * pixels));
    assert_eq!(truth, (Stage::Truth, 0));
    assert_eq!(out.geometry, reference.geometry, "geometry");
    assert_eq!(out.ids, reference.ids, "ids");
    // Each pixel: its centre where the lens covers it, then those of its samples it covers.
    for (i, (&n, c)) in rays.iter().zip(&reference.colour).enumerate() {
        let samples = (c[3] * spp as f32).round() as u32;
        assert_eq!(n, u32::from(centres.valid(i)) + samples, "pixel {i}");
    }
}

/// An image so small that the lens's circle holds no block corner (5 × 7 and 2 × 3 pixels
/// through the 180° lens: every lattice point masked) is still traced where the lens covers
/// it: at threshold 0, uniform sampling's image and one ray a covered pixel (it was once
/// interpolated as all masked, a blank frame).
#[test]
fn a_circle_smaller_than_a_block_is_traced() {
    let room = scene("builtin:default");
    let gpu = upload(&room);
    for (w, h) in [(5, 7), (2, 3)] {
        let cam = camera("canon-8-15mm@8mm", w, h);
        let reference = uniform(&gpu, &cam, 1);
        let covered = reference.counts().0;
        assert!(covered > 0, "{w}x{h}: the lens covers some pixels");
        let (out, rays) = adaptive(&gpu, &cam, 1, 0.0, false);
        assert_eq!(out.colour, reference.colour, "{w}x{h}");
        let traced = rays.iter().filter(|&&n| n == 1).count();
        assert_eq!(traced, covered, "{w}x{h}: {rays:?}");
    }
}

/// Interpolated pixels get their first hits traced: ids, normals and ranges are never
/// interpolated, and equal uniform sampling's bit for bit.
#[test]
fn ground_truth_is_uniform_samplings() {
    let room = scene("builtin:default");
    let gpu = upload(&room);
    let cam = camera("samyang-7.5mm", 64, 48);
    let reference = uniform(&gpu, &cam, 4);
    let (out, rays) = adaptive(&gpu, &cam, 4, 0.05, true);
    assert!(rays.contains(&0), "some pixels were interpolated");
    assert_eq!(out.geometry, reference.geometry);
    assert_eq!(out.ids, reference.ids);
    // Without it, the interpolated pixels have none.
    let (bare, rays) = adaptive(&gpu, &cam, 4, 0.05, false);
    for (i, &n) in rays.iter().enumerate() {
        if n == 0 && bare.valid(i) {
            assert_eq!(
                (bare.ids[i], bare.geometry[i]),
                (NO_HIT, [0.0; 4]),
                "pixel {i}"
            );
        }
    }
}

#[test]
fn reruns_are_bit_identical() {
    let room = scene("builtin:default");
    let gpu = upload(&room);
    let cam = camera("canon-8-15mm@8mm", 80, 60);
    let (a, rays_a) = adaptive(&gpu, &cam, 16, 0.03, true);
    let (b, rays_b) = adaptive(&gpu, &cam, 16, 0.03, true);
    assert_eq!(a.colour, b.colour);
    assert_eq!(a.ids, b.ids);
    assert_eq!(rays_a, rays_b);
}

/// Pixels on a silhouette (their centre's hit and a neighbour's differ between something and
/// sky) take many rays; pixels of open sky, far from any object, take almost none.
#[test]
fn edges_get_more_rays_than_flat_pixels() {
    let boxes = scene("builtin:many-small");
    let gpu = upload(&boxes);
    let (w, h) = (96, 72);
    let cam = camera("canon-8-15mm@8mm", w, h);
    let truth = uniform(&gpu, &cam, 1);
    let (_, rays) = adaptive(&gpu, &cam, 16, 0.05, false);
    let (w, h) = (w as usize, h as usize);
    let sky = |x: usize, y: usize| truth.valid(y * w + x) && truth.ids[y * w + x] == NO_HIT;
    let (mut edge, mut open) = (Vec::new(), Vec::new());
    for y in 2..h - 2 {
        for x in 2..w - 2 {
            let i = y * w + x;
            let hit = truth.ids[i] != NO_HIT;
            if truth.valid(i)
                && hit
                && [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)]
                    .iter()
                    .any(|&(a, b)| sky(a, b))
            {
                edge.push(rays[i]);
            }
            if (y - 2..=y + 2).all(|b| (x - 2..=x + 2).all(|a| sky(a, b))) {
                open.push(rays[i]);
            }
        }
    }
    let mean = |v: &[u32]| v.iter().map(|&n| f64::from(n)).sum::<f64>() / v.len() as f64;
    assert!(
        edge.len() > 20 && open.len() > 200,
        "{} edge, {} open",
        edge.len(),
        open.len()
    );
    let (on_edges, in_sky) = (mean(&edge), mean(&open));
    assert!(
        on_edges >= 8.0,
        "silhouette pixels took {on_edges:.2} rays on average"
    );
    assert!(in_sky <= 0.25, "open sky took {in_sky:.2} rays a pixel");
}

/// A pixel on the lens's edge (its centre covered and a neighbour's masked, or the other way
/// round) is supersampled whatever the threshold: at threshold 1, where colour alone picks
/// almost nothing, each such pixel that has a ray of its own takes the 2 × 2 samples uniform
/// sampling takes (a covered one its centre too), and so has uniform sampling's colour.
#[test]
fn pixels_on_the_lens_edge_are_supersampled() {
    let room = scene("builtin:default");
    let gpu = upload(&room);
    let (w, h) = (61u32, 46u32);
    let cam = camera("canon-8-15mm@8mm", w, h);
    let reference = uniform(&gpu, &cam, 4);
    let centres = uniform(&gpu, &cam, 1);
    let (out, rays) = adaptive(&gpu, &cam, 4, 1.0, false);
    let (w, h) = (w as usize, h as usize);
    let (mut covered, mut masked) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let inside = centres.valid(i);
            let neighbours = [
                (x.wrapping_sub(1), y),
                (x + 1, y),
                (x, y.wrapping_sub(1)),
                (x, y + 1),
            ];
            let across = neighbours
                .iter()
                .any(|&(a, b)| a < w && b < h && centres.valid(b * w + a) != inside);
            if !across || (inside && rays[i] == 0) {
                continue;
            }
            let samples = (reference.colour[i][3] * 4.0).round() as u32;
            assert_eq!(out.colour[i], reference.colour[i], "pixel ({x}, {y})");
            assert_eq!(rays[i], u32::from(inside) + samples, "pixel ({x}, {y})");
            if inside {
                covered += 1;
            } else {
                masked += 1;
            }
        }
    }
    // The 180° circle's rim at 61x46: about 2π·23 pixels on each side of it.
    assert!(
        covered > 60 && masked > 60,
        "{covered} covered, {masked} masked"
    );
}

/// Lower thresholds refine more, so the error against a 64-ray reference falls (to uniform
/// sampling's at threshold 0).
#[test]
fn error_falls_as_the_threshold_falls() {
    let room = scene("builtin:default");
    let gpu = upload(&room);
    let cam = camera("canon-8-15mm@8mm", 80, 60);
    let reference = uniform(&gpu, &cam, 64);
    let mut last: Option<(f32, f64, f64)> = None;
    for threshold in [0.3, 0.1, 0.03, 0.01, 0.0] {
        let (out, rays) = adaptive(&gpu, &cam, 16, threshold, false);
        let mse = image_error(&reference.colour, &out.colour).mse;
        let spent = rays.iter().map(|&n| f64::from(n)).sum::<f64>();
        if let Some((before, mse_before, spent_before)) = last {
            assert!(
                spent >= spent_before,
                "{threshold} spent fewer rays than {before}"
            );
            assert!(
                mse <= mse_before,
                "MSE {mse:.3e} at {threshold}, above {mse_before:.3e} at {before}"
            );
        }
        last = Some((threshold, mse, spent));
    }
}

/// Above threshold 0, a pixel the estimating stage samples 2 × 2 and leaves is uniform
/// sampling's 4-ray pixel, and one it goes on to supersample is the 16-ray pixel, bit for bit
/// (the same samples, added in the same order, whether traced side by side or an invocation
/// a pixel; supersampling takes 12 more after the estimate's 4, the start of the 16's nested
/// pattern): both kinds occur. The scene is untextured: the estimate's samples filter
/// textures at their own 2 × 2 spacing, so where a supersampled pixel sees a texture its
/// first four samples are a little blurrier than uniform sampling's 16's.
#[test]
fn estimated_and_supersampled_pixels_are_uniform_samplings() {
    let room = scene("scenes/cornell-box.toml");
    let gpu = upload(&room);
    let cam = camera("canon-8-15mm@8mm", 80, 60);
    let (four, sixteen) = (uniform(&gpu, &cam, 4), uniform(&gpu, &cam, 16));
    for lanes in [SampleLanes::PerSample, SampleLanes::PerPixel] {
        let (out, rays, _) = adaptive_laid_out(&gpu, &cam, (16, 0.05, false), lanes);
        estimated_and_supersampled_match(&out, &rays, (&four, &sixteen));
    }
}

/// The checks of [`estimated_and_supersampled_pixels_are_uniform_samplings`] on one frame
/// (`out`, each pixel's `rays`) against uniform sampling's 4- and 16-ray frames.
fn estimated_and_supersampled_match(
    out: &RenderOutput,
    rays: &[u32],
    (four, sixteen): (&RenderOutput, &RenderOutput),
) {
    let (mut estimated, mut supersampled) = (0, 0);
    for (i, &n) in rays.iter().enumerate() {
        // Pixels the lens covers whole: their centre's ray, then 4, then 12 more samples.
        if out.colour[i][3] != 1.0 {
            continue;
        }
        if n == 1 + 4 {
            assert_eq!(out.colour[i], four.colour[i], "pixel {i}, estimated");
            estimated += 1;
        } else if n == 1 + 4 + 12 {
            assert_eq!(out.colour[i], sixteen.colour[i], "pixel {i}, supersampled");
            supersampled += 1;
        }
    }
    assert!(
        estimated > 0 && supersampled > 0,
        "{estimated} estimated, {supersampled} supersampled"
    );
}

/// Starting from every pixel's centre (`auto:T:MAX:1`) the frame is coarse, estimating and
/// supersampling stages alone, the first a ray through every pixel; each pixel is then
/// uniform sampling's at its own rays, bit for bit: one ray (its centre), 1 + 4 (the
/// estimate's 2 × 2) or 1 + 16, and each of the three occurs; no pixel is interpolated, so
/// the ground truth is uniform sampling's with no stage of its own; at threshold 0 the frame
/// is 16 uniform rays'; a rerun gives the same bits; and progressive steps begin at uniform
/// sampling's one-ray frame and end in the whole frame.
#[test]
fn every_pixel_first_gives_uniform_sampling_at_each_pixels_rays() {
    let room = scene("scenes/cornell-box.toml");
    let gpu = upload(&room);
    let (w, h) = (80u32, 60u32);
    let cam = camera("canon-8-15mm@8mm", w, h);
    let (one, four, sixteen) = (
        uniform(&gpu, &cam, 1),
        uniform(&gpu, &cam, 4),
        uniform(&gpu, &cam, 16),
    );
    let lanes = SampleLanes::for_device(&ctx().device);
    let every = |threshold| Adaptive {
        threshold,
        ground_truth: true,
        every_pixel: true,
    };
    let (out, rays, stages) = adaptive_with(&gpu, &cam, 16, every(0.05), lanes);
    let names: Vec<Stage> = stages.iter().map(|&(stage, _)| stage).collect();
    assert_eq!(
        names,
        [Stage::Coarse, Stage::Estimate, Stage::Supersample],
        "{stages:?}"
    );
    assert_eq!(stages[0].1, u64::from(w * h), "a ray through every pixel");
    for (i, &n) in rays.iter().enumerate() {
        // Every pixel whose centre the lens covers (pixels on the lens's edge whose centre
        // it masks may take the estimate's samples it covers).
        assert!(n >= 1 || !one.valid(i), "pixel {i}: {n} rays");
    }
    // Pixels the lens covers whole (the others' samples are partly masked).
    let whole = |i: usize| out.colour[i][3] == 1.0;
    each_pixel_uniform_at_its_rays(&out, &rays, [&one, &four, &sixteen], whole);
    assert_eq!(out.geometry, one.geometry, "geometry");
    assert_eq!(out.ids, one.ids, "ids");
    let (again, rays_again, _) = adaptive_with(&gpu, &cam, 16, every(0.05), lanes);
    assert_eq!((&again.colour, &rays_again), (&out.colour, &rays), "rerun");
    let (exact, _, _) = adaptive_with(&gpu, &cam, 16, every(0.0), lanes);
    assert_eq!(exact.colour, sixteen.colour, "threshold 0");
    // Progressively: the first step is uniform sampling's one-ray frame, and the steps end in
    // the whole frame (16 samples a pixel at most: step 1 and at most 16 slices).
    let source = DirectionSource::Computed;
    let pass = AdaptivePass::with_lanes(ctx(), &cam, &gpu, source, 16, every(0.05), lanes).unwrap();
    let step = |k: u32| {
        let mut encoder = ctx().device.create_command_encoder(&Default::default());
        pass.encode_step(&mut encoder, &gpu, k);
        ctx().queue.submit([encoder.finish()]);
    };
    let image = || pass.trace_pass().read(ctx()).unwrap().colour;
    step(0);
    assert_eq!(image(), one.colour, "step 0");
    (1..=17).for_each(step);
    assert_eq!(image(), out.colour, "the steps' end");
}

/// Checks that each pixel of `out` that `judged` names and that took rays of its own (`rays`)
/// took 1, 1 + 4 or 1 + 16 (the estimate's four reused) and is then `one`'s, `four`'s or
/// `sixteen`'s (uniform sampling at those rays) bit for bit, and that each of the three occurs.
fn each_pixel_uniform_at_its_rays(
    out: &RenderOutput,
    rays: &[u32],
    [one, four, sixteen]: [&RenderOutput; 3],
    judged: impl Fn(usize) -> bool,
) {
    let mut seen = [0; 3];
    for (i, &n) in rays.iter().enumerate() {
        if n == 0 || !judged(i) {
            continue;
        }
        let (wanted, kind) = match n {
            1 => (one, 0),
            5 => (four, 1),
            17 => (sixteen, 2),
            _ => panic!("pixel {i}: {n} rays"),
        };
        assert_eq!(out.colour[i], wanted.colour[i], "pixel {i}, {n} rays");
        seen[kind] += 1;
    }
    assert!(seen.iter().all(|&k| k > 0), "1, 5 and 17 rays: {seen:?}");
}

/// Supersampling takes the pixels that demand every sample (`AdaptivePass::read_demanding`)
/// and estimated pixels beside them across a change of surface, and no others: on the pixels
/// the lens covers whole, where an estimated pixel took 1 + 4 rays and a supersampled one
/// 1 + 16, each supersampled pixel demands or has a demanding neighbour (left, right, above or
/// below); an estimated pixel with a demanding neighbour that sees the sky where it sees a
/// surface, or the other way round, is supersampled; and one whose demanding neighbours all
/// hit its own flat triangle (the same id and normal: one plane) is left at its 4. Pixels
/// supersampled for a silhouette beside them occur, and pixels left beside a demanding one.
#[test]
fn estimated_pixels_beside_demanding_ones_across_an_edge_are_supersampled() {
    let gpu = upload(&scene("builtin:many-small"));
    let (w, h) = (96usize, 72usize);
    let cam = camera("canon-8-15mm@8mm", w as u32, h as u32);
    let whole = uniform(&gpu, &cam, 16);
    let options = Adaptive {
        threshold: 0.05,
        ground_truth: false,
        every_pixel: false,
    };
    let pass =
        AdaptivePass::new(ctx(), &cam, &gpu, DirectionSource::Computed, 16, options).unwrap();
    let out = pass.trace(ctx(), &gpu, "adaptive").unwrap();
    let (rays, demanding) = (
        pass.read_rays(ctx()).unwrap(),
        pass.read_demanding(ctx()).unwrap(),
    );
    let (mut across_sky, mut left) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if whole.colour[i][3] != 1.0 || rays[i] < 1 + 4 {
                continue;
            }
            let supersampled = match rays[i] {
                5 => false,
                17 => true,
                n => panic!("pixel ({x}, {y}) took {n} rays"),
            };
            if demanding[i] {
                assert!(supersampled, "pixel ({x}, {y}) demands but took 4");
                continue;
            }
            let beside: Vec<usize> = [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)]
                .iter()
                .map(|&(dx, dy)| (x as i64 + dx, y as i64 + dy))
                .filter(|&(a, b)| (0..w as i64).contains(&a) && (0..h as i64).contains(&b))
                .map(|(a, b)| b as usize * w + a as usize)
                .filter(|&j| demanding[j])
                .collect();
            let sky = |j: usize| out.ids[j] == NO_HIT;
            if beside.iter().any(|&j| sky(j) != sky(i)) {
                assert!(supersampled, "pixel ({x}, {y}) beside a silhouette took 4");
                across_sky += 1;
            } else if !beside.is_empty()
                && !sky(i)
                && beside.iter().all(|&j| {
                    out.ids[j] == out.ids[i] && out.geometry[j][..3] == out.geometry[i][..3]
                })
            {
                assert!(
                    !supersampled,
                    "pixel ({x}, {y}) supersampled within its triangle"
                );
                left += 1;
            } else if beside.is_empty() {
                assert!(
                    !supersampled,
                    "pixel ({x}, {y}) supersampled with no demanding neighbour"
                );
            }
        }
    }
    assert!(
        across_sky > 0 && left > 0,
        "{across_sky} across the sky, {left} left at 4"
    );
}

/// What adaptive sampling cannot do is refused with what to do instead: a negative or
/// non-finite threshold, and an image whose outputs exceed one storage binding (uniform
/// sampling traces those in bands).
#[test]
fn adaptive_sampling_refuses_what_it_cannot_do() {
    let gpu = upload(&scene("builtin:default"));
    let refuse = |cam: &LensCamera, threshold: f32| {
        let options = Adaptive {
            threshold,
            ground_truth: false,
            every_pixel: false,
        };
        let source = DirectionSource::Computed;
        match AdaptivePass::new(ctx(), cam, &gpu, source, 1, options) {
            Ok(_) => panic!("threshold {threshold} at {} was accepted", cam.size),
            Err(e) => e.to_string(),
        }
    };
    let small = camera("canon-8-15mm@8mm", 32, 24);
    for bad in [-0.1, f32::NAN, f32::INFINITY] {
        assert!(refuse(&small, bad).contains("0 or more"), "{bad}");
    }
    let limit = ctx().device.limits().max_storage_buffer_binding_size;
    let rows = (limit / (16 * 4096)) as u32 + 1;
    let message = refuse(&camera("equidistant:f=0.6", 4096, rows), 0.05);
    assert!(
        message.contains("one storage binding") && message.contains("--spp N"),
        "{message}"
    );
}

/// Progressive refinement (`AdaptivePass::encode_step`): step 0 is the frame below one ray a
/// pixel that `--spp auto:T:1` makes; each later step spends about one ray a pixel (at most
/// one slice of pixels × the most samples); the steps end in the whole adaptive frame, every
/// output bit for bit, after which a step changes nothing.
#[test]
fn progressive_steps_sharpen_into_the_adaptive_frame() {
    let room = scene("builtin:default");
    let gpu = upload(&room);
    let cam = camera("canon-8-15mm@8mm", 61, 46);
    let (threshold, spp) = (0.02, 16);
    let options = Adaptive {
        threshold,
        ground_truth: true,
        every_pixel: false,
    };
    let pass =
        AdaptivePass::new(ctx(), &cam, &gpu, DirectionSource::Computed, spp, options).unwrap();
    let step = |k: u32| {
        let mut encoder = ctx().device.create_command_encoder(&Default::default());
        pass.encode_step(&mut encoder, &gpu, k);
        ctx().queue.submit([encoder.finish()]);
        let out = pass.trace_pass().read(ctx()).unwrap();
        let rays = pass.read_rays(ctx()).unwrap();
        (out, rays.iter().map(|&n| u64::from(n)).sum::<u64>(), rays)
    };
    let (first, mut spent, first_rays) = step(0);
    // Step 0 is the auto:T:1 frame, but for the pixels that frame interpolates between two
    // agreeing corners of a half-block an edge crosses: a frame that may supersample traces
    // them (whether they need it shows in their own colour), and they have one ray's colour.
    let (coarse, coarse_rays) = adaptive(&gpu, &cam, 1, threshold, true);
    let one_ray = uniform(&gpu, &cam, 1);
    assert_eq!(
        first.ids, coarse.ids,
        "step 0 has the auto:T:1 frame's ground truth"
    );
    let mut beside_edges = 0;
    for (i, (&n, &m)) in first_rays.iter().zip(&coarse_rays).enumerate() {
        if (n, m) == (1, 0) {
            beside_edges += 1;
            assert_eq!(first.colour[i], one_ray.colour[i], "pixel {i}'s colour");
        } else {
            assert_eq!(n, m, "pixel {i}'s rays");
            assert_eq!(first.colour[i], coarse.colour[i], "pixel {i}'s colour");
        }
    }
    assert!(
        beside_edges > 0,
        "no pixel beside an edge traced at step 0 alone"
    );
    let pixels = cam.size.pixels() as u64;
    assert!(spent < pixels, "step 0 is below a ray a pixel: {spent}");

    let (whole, whole_rays) = adaptive(&gpu, &cam, spp, threshold, true);
    let slice = pixels / u64::from(spp);
    let mut last = first;
    let mut slices = 0;
    for k in 1.. {
        let (out, total, rays) = step(k);
        let added = total - spent;
        // Step 1 takes the 2 × 2 estimating samples of the pixels whose colour bends.
        let budget = if k == 1 {
            4 * pixels
        } else {
            slice * u64::from(spp)
        };
        assert!(added <= budget, "step {k}: {added} rays, above {budget}");
        if k > 1 && added == 0 {
            // Done: nothing left, so nothing changed, and it is the whole frame.
            assert_eq!(out.colour, last.colour, "step {k}");
            assert_eq!(out.colour, whole.colour, "colour");
            assert_eq!(out.geometry, whole.geometry, "geometry");
            assert_eq!(out.ids, whole.ids, "ids");
            assert_eq!(rays, whole_rays, "rays");
            break;
        }
        slices += u32::from(k > 1);
        assert!(k < 2 + 16 + 1, "still refining after {k} steps");
        (last, spent) = (out, total);
    }
    assert!(slices > 1, "the list took several steps: {slices}");
}
