//! `fisheye validate` as a library: every preset and calibrated example, rendered through the
//! GPU tracer, puts the grid's corners where its f64 projection says, within the stated
//! bound; and models a little off are caught.

mod common;

use common::ctx;
use fisheye_rt::lens::{CalibratedLens, CalibratedModel, Intrinsics, Lens, LensCamera, parse_spec};
use fisheye_rt::trace::{GpuScene, RenderOptions};
use fisheye_rt::validate::{self, BOUND_PX, Image, LensValidation, evaluate, pose, predict};

fn grid() -> GpuScene {
    let scene = fisheye_rt::scene::builtin::scene("grid").unwrap();
    GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap()
}

/// Renders through `rendered` and checks the corners against `model`'s projection.
fn check(scene: &GpuScene, rendered: &LensCamera, model: &LensCamera) -> LensValidation {
    let colour = validate::render(ctx(), scene, rendered, 4).unwrap();
    let image = Image::from_colour(rendered.size.width as usize, &colour);
    let predictions = predict(model, &pose(), &image);
    evaluate("test", model, &predictions, &image.corners())
}

/// Every preset and every calibrated model's example passes: each checked corner (more than
/// a hundred per lens) is found within the bound, and nothing else is found among them.
#[test]
fn every_preset_and_calibrated_example_passes() {
    let lenses = validate::default_lenses().unwrap();
    assert_eq!(lenses.len(), 7 + CalibratedModel::EXAMPLES.len());
    // Half the lenses on each of two threads, with a device each (`ctx`): most of the time
    // is lavapipe compiling each lens's kernels, one core each.
    let (first, second) = lenses.split_at(lenses.len() / 2);
    let reports = std::thread::scope(|scope| {
        [first, second]
            .map(|half| scope.spawn(|| validate::run(ctx(), half, Some(4), &mut |_, _| {})))
            .map(|thread| thread.join().unwrap().unwrap())
    });
    assert!(reports.iter().all(|r| r.passed()));
    let checked: Vec<_> = reports.iter().flat_map(|r| &r.lenses).collect();
    assert_eq!(checked.len(), lenses.len());
    for l in checked.iter().copied() {
        eprintln!(
            "{}: {} checked, rms {:.4} px, max {:.4} px, out to {:.1}°",
            l.lens, l.checked, l.rms_px, l.max_px, l.max_theta_deg
        );
        assert!(
            l.checked > 100,
            "{}: only {} corners checked",
            l.lens,
            l.checked
        );
        assert_eq!(l.matched, l.checked, "{}", l.lens);
        assert_eq!(l.stray, 0, "{}", l.lens);
        assert!(l.max_px <= BOUND_PX, "{}: {} px", l.lens, l.max_px);
        // No systematic shift: a pixel-convention error would show here first.
        assert!(l.mean_px[0].hypot(l.mean_px[1]) < 0.01, "{}", l.lens);
        assert!(l.passed);
    }
    // The calibrated examples that reach past 90° are checked past it.
    assert!(checked.iter().any(|l| l.max_theta_deg > 95.0));
}

/// A model 0.1 % off in focal length, or with the principal point half a pixel off (the
/// OpenCV centre-convention mistake), fails where the right one passes.
#[test]
fn a_slightly_wrong_model_fails() {
    let scene = grid();
    let spec = CalibratedModel::EXAMPLES[0];
    let right = common::camera(spec, 512, 512);
    let good = check(&scene, &right, &right);
    assert!(good.passed, "{good:?}");
    let Lens::Calibrated(lens) = parse_spec(spec).unwrap() else {
        panic!("{spec} is calibrated")
    };
    let i = lens.intrinsics();
    let with = |intrinsics| {
        LensCamera::new(
            CalibratedLens::new(lens.model(), intrinsics).unwrap(),
            right.size,
        )
    };
    let longer = with(Intrinsics {
        fx: i.fx * 1.001,
        fy: i.fy * 1.001,
        ..i
    });
    let shifted = with(Intrinsics {
        cx: i.cx + 0.5,
        ..i
    });
    for (what, wrong) in [("f × 1.001", longer), ("cx + 0.5 px", shifted)] {
        let bad = check(&scene, &right, &wrong);
        eprintln!("{what}: max {:.3} px", bad.max_px);
        assert!(!bad.passed, "{what}");
        assert!(bad.max_px > 2.0 * BOUND_PX, "{what}: {}", bad.max_px);
    }
}
