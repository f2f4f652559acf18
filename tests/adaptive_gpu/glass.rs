//! Adaptive sampling through a prescription's glass: each film sample's ray goes through the
//! surfaces toward its point of the exit pupil, as uniform sampling's do, so every pixel is
//! uniform sampling's at its own rays, and the ground truth is the fitted model's centre ray.

use super::*;

/// Muller's fisheye (`lenses/fisheye-10mm.dat`) at `w` × `h`, traced through its glass.
fn through_glass(w: u32, h: u32) -> LensCamera {
    let spec = format!(
        "prescription:{}/lenses/fisheye-10mm.dat",
        env!("CARGO_MANIFEST_DIR")
    );
    let size = fisheye_rt::lens::ImageSize::new(w, h).unwrap();
    let cam = fisheye_rt::lens::glass::camera_for(&spec, size).unwrap();
    assert!(cam.glass.is_some(), "traced through the glass");
    cam
}

/// Through the glass, an adaptive frame is made of uniform sampling's pixels: at threshold 0,
/// uniform sampling at 16 rays bit for bit (both layouts of the samples over invocations);
/// above it, a pixel traced at its centre alone is uniform sampling's one-ray pixel (a film
/// sample at its centre toward a point of the pupil), an estimated one its 4-ray pixel and a
/// supersampled one its 16-ray pixel, each bit for bit and each occurring. Supersampling goes
/// on from the estimate's samples (the pupil's points are nested as the film's are), so a
/// supersampled pixel took 1 + 4 + 12 rays, and the supersampling stage counts 12 a pixel.
/// The ground truth is the fitted model's centre ray, as uniform sampling's, and a rerun gives
/// the same bits.
#[test]
fn through_a_prescriptions_glass_each_pixel_is_uniform_samplings() {
    let gpu = upload(&scene("builtin:default"));
    let (w, h) = (48u32, 36u32);
    let cam = through_glass(w, h);
    let (one, four, sixteen) = (
        uniform(&gpu, &cam, 1),
        uniform(&gpu, &cam, 4),
        uniform(&gpu, &cam, 16),
    );
    for lanes in [SampleLanes::PerSample, SampleLanes::PerPixel] {
        let (exact, _, _) = adaptive_laid_out(&gpu, &cam, (16, 0.0, true), lanes);
        assert_eq!(exact.colour, sixteen.colour, "threshold 0, {lanes:?}");
        assert_eq!(
            (&exact.geometry, &exact.ids),
            (&sixteen.geometry, &sixteen.ids)
        );
    }
    let lanes = SampleLanes::for_device(&ctx().device);
    let every = Adaptive {
        threshold: 0.05,
        ground_truth: true,
        every_pixel: true,
    };
    let lattice = Adaptive {
        every_pixel: false,
        ..every
    };
    for options in [every, lattice] {
        let (out, rays, stages) = adaptive_with(&gpu, &cam, 16, options, lanes);
        // Every pixel with rays of its own (the others are interpolated or masked).
        each_pixel_uniform_at_its_rays(&out, &rays, [&one, &four, &sixteen], |_| true);
        // Twelve a listed pixel, those on the lens's rim that its centre masks included.
        let supersampled = stages
            .iter()
            .find(|(s, _)| *s == Stage::Supersample)
            .unwrap();
        let took_all = rays.iter().filter(|&&n| n == 17).count() as u64;
        assert!(
            supersampled.1 % 12 == 0 && supersampled.1 >= 12 * took_all,
            "{stages:?}"
        );
        assert_eq!((&out.geometry, &out.ids), (&one.geometry, &one.ids));
        let (again, rays_again, _) = adaptive_with(&gpu, &cam, 16, options, lanes);
        assert_eq!((&again.colour, &rays_again), (&out.colour, &rays), "rerun");
    }
}
