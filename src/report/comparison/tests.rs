use super::verdicts::{ceiling, verdict};
use super::*;
use crate::compare::ImageError;

/// The warm-up runs at least one frame, and frames until its time has passed: frames of
/// at least 5 ms fill 20 ms in no fewer than 4. A frame's error ends it.
#[test]
fn the_warm_up_runs_frames_until_its_time_has_passed() {
    assert_eq!(warm_up(Duration::ZERO, || Ok(())).unwrap(), 1);
    let start = Instant::now();
    let frames = warm_up(Duration::from_millis(20), || {
        std::thread::sleep(Duration::from_millis(5));
        Ok(())
    })
    .unwrap();
    assert!(frames >= 4, "{frames} frames");
    assert!(start.elapsed() >= Duration::from_millis(20));
    let mut calls = 0;
    let failed = warm_up(Duration::from_secs(60), || {
        calls += 1;
        Err(crate::error::Error::Option("no adapter".into()))
    });
    assert!(failed.is_err() && calls == 1);
}

/// Each round times every setup once; any n rounds in a row put each setup in every place
/// of the round once (a Latin square), so no setup is always timed first or last.
#[test]
fn rounds_time_every_setup_once_in_turning_order() {
    for n in 1..7 {
        for start in [0, 3, 10] {
            let mut places = vec![vec![0; n]; n];
            for r in start..start + n {
                let order: Vec<usize> = round_order(r, n).collect();
                let mut sorted = order.clone();
                sorted.sort_unstable();
                assert_eq!(sorted, (0..n).collect::<Vec<_>>(), "round {r} of {n}");
                for (place, &setup) in order.iter().enumerate() {
                    places[setup][place] += 1;
                }
            }
            assert!(places.iter().flatten().all(|&k| k == 1), "{n}: {places:?}");
        }
    }
}

/// A setup (`rt@Nspp`, `cube-rt@SIZE` or `cube-forward@SIZE`) with a time (GPU, else wall),
/// an MSE and a ꟻLIP; RT traces a thousand pixels, and a cube's faces have SIZE² texels.
fn entry(setup: &str, gpu_ms: Option<f64>, wall_ms: f64, mse: f64) -> CompareEntry {
    let error = ImageError {
        mse,
        psnr_db: -10.0 * mse.log10(),
        max_abs: mse.sqrt(),
        mask_agreement: 1.0,
        compared: 1,
    };
    let (method, after) = setup.split_once('@').unwrap();
    let (cube_size, spp) = match after.strip_suffix("spp") {
        Some(spp) => (None, Some(spp.parse().unwrap())),
        None => (Some(after.parse().unwrap()), None),
    };
    let samples = match (spp, cube_size) {
        (Some(spp), _) => f64::from(spp) * 1000.0,
        (_, Some(size)) => f64::from(size * size),
        _ => unreachable!(),
    };
    CompareEntry {
        lens: "lens".into(),
        setup: setup.into(),
        method: ["rt", "cube-rt", "cube-forward"]
            .into_iter()
            .find(|&m| m == method)
            .unwrap(),
        cube_size,
        spp,
        threshold: None,
        filter: cube_size.is_none().then_some("box"),
        rays_per_pixel: spp.map(f64::from),
        samples,
        gpu_ms,
        wall_ms,
        error,
        flip: mse.sqrt(),
        pareto: false,
        pareto_flip: false,
    }
}

/// RT at 1, 4 and 16 rays per pixel: 10, 40, 160 ms for MSE 4e-3, 1e-3, 2.5e-4 (4x the
/// time for a quarter of the error), against cube maps whose errors fall slower.
fn family() -> Vec<CompareEntry> {
    vec![
        entry("rt@1spp", Some(10.0), 50.0, 4e-3),
        entry("rt@4spp", Some(40.0), 90.0, 1e-3),
        entry("rt@16spp", Some(160.0), 200.0, 2.5e-4),
        entry("cube-rt@64", Some(5.0), 1.0, 8e-3),
        entry("cube-rt@128", Some(40.0), 1.0, 2e-3),
        // Dominated by 128: off the envelope, and no level of its own.
        entry("cube-rt@192", Some(60.0), 1.0, 3e-3),
        entry("cube-rt@256", Some(200.0), 1.0, 5e-4),
        // Slower than the traced 128 for its error, and no rays: in neither verdict.
        entry("cube-forward@3", Some(100.0), 1.0, 2e-3),
    ]
}

/// The verdict's levels are the cube setups on their envelope; at each, RT's time comes
/// from its own envelope: its fastest setup above RT's 1-ray error, log-log interpolation
/// between its setups otherwise.
#[test]
fn the_verdict_compares_the_families_at_the_cubes_errors() {
    let v = verdict("lens", &family(), Metric::Mse).unwrap();
    let cubes: Vec<&str> = v.levels.iter().map(|l| l.cube.as_str()).collect();
    assert_eq!(cubes, ["cube-rt@64", "cube-rt@128", "cube-rt@256"]);
    // 8e-3: RT's 1 ray is good enough, 10 ms; 5 ms of cube map is 0.5x.
    assert_eq!(v.levels[0].rt_ms, Some(10.0));
    assert_eq!(v.levels[0].speedup, Some(0.5));
    // 2e-3 lies halfway (in log) between 4e-3 and 1e-3: 20 ms, so 40 / 20 = 2x.
    assert!((v.levels[1].rt_ms.unwrap() - 20.0).abs() < 1e-9);
    assert!((v.levels[1].speedup.unwrap() - 2.0).abs() < 1e-9);
    // 5e-4 halfway between 1e-3 and 2.5e-4: 80 ms, 2.5x.
    assert!((v.levels[2].speedup.unwrap() - 2.5).abs() < 1e-9);
    assert_eq!(v.least_speedup, Some(0.5));
    // RT goes lower than any cube map.
    assert_eq!(v.rt_only, Some((2.5e-4, "rt@16spp".to_string())));
    assert_eq!(v.metric, Metric::Mse);

    // In samples, against the traced cubes alone: 4096 texels at 8e-3, where RT's fastest
    // setup traces 1000 rays; 2000 rays (halfway in log from 1000 to 4000) at 2e-3 against
    // 16384 texels, and 8000 at 5e-4 against 65536.
    let cubes: Vec<&str> = v.rays.iter().map(|l| l.cube.as_str()).collect();
    assert_eq!(cubes, ["cube-rt@64", "cube-rt@128", "cube-rt@256"]);
    let rays: Vec<f64> = v.rays.iter().map(|l| l.rt_rays.unwrap()).collect();
    for (r, want) in rays.iter().zip([1000.0, 2000.0, 8000.0]) {
        assert!((r - want).abs() < 1e-6, "{rays:?}");
    }
    assert_eq!(v.rays[0].texels, 4096.0);
    assert!((v.rays[2].fewer.unwrap() - 65536.0 / 8000.0).abs() < 1e-9);
    assert_eq!(v.least_fewer, Some(4.096));

    // Without RT's 16 rays, the 256 cube's error is one only the cube maps reach.
    let mut fewer = family();
    fewer.remove(2);
    let v = verdict("lens", &fewer, Metric::Mse).unwrap();
    assert_eq!((v.levels[2].rt_ms, v.levels[2].speedup), (None, None));
    assert_eq!((v.rays[2].rt_rays, v.rays[2].fewer), (None, None));
    assert_eq!(v.rt_only, None);

    // No traced cube, no verdict in samples.
    let raster: Vec<CompareEntry> = family()
        .into_iter()
        .filter(|e| e.method != "cube-rt")
        .collect();
    let v = verdict("lens", &raster, Metric::Mse).unwrap();
    assert!(v.rays.is_empty() && v.least_fewer.is_none());

    // Wall times where nothing has timestamps; no verdict without both families.
    let walls = [
        entry("rt@1spp", None, 8.0, 0.01),
        entry("cube-rt@64", None, 4.0, 0.01),
    ];
    let v = verdict("lens", &walls, Metric::Mse).unwrap();
    assert_eq!(v.levels[0].speedup, Some(0.5));
    assert!(verdict("lens", &walls[1..], Metric::Mse).is_none());
    assert!(verdict("lens", &walls[..1], Metric::Mse).is_none());
}

/// The ceiling is the cube maps' fastest frame over RT's: on `family`, 5 ms of the 64-texel
/// cube over RT's 1 ray's 10 ms, which reaches that cube's error, so the least speed-up is
/// the ceiling. Where RT's fastest frame misses the coarsest cube's error it needs more time
/// there, and the least falls below the ceiling; over families of any times and errors it
/// never exceeds it. No ceiling without both families.
#[test]
fn no_least_speed_up_exceeds_the_ceiling() {
    let c = ceiling("lens", &family()).unwrap();
    assert_eq!(
        (c.cube.as_str(), c.cube_ms, c.rt.as_str(), c.rt_ms, c.ratio),
        ("cube-rt@64", 5.0, "rt@1spp", 10.0, 0.5)
    );
    assert_eq!(
        verdict("lens", &family(), Metric::Mse)
            .unwrap()
            .least_speedup,
        Some(0.5)
    );

    let mut coarse = family();
    coarse[0].error.mse = 1e-2;
    let v = verdict("lens", &coarse, Metric::Mse).unwrap();
    assert!(v.least_speedup.unwrap() < ceiling("lens", &coarse).unwrap().ratio);

    // A small linear congruential generator: values in [0, 1).
    let mut state = 12345u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let names = [
        "rt@1spp",
        "rt@4spp",
        "rt@16spp",
        "cube-rt@64",
        "cube-rt@128",
        "cube-forward@3",
    ];
    let mut compared = 0;
    for _ in 0..500 {
        let entries: Vec<CompareEntry> = names
            .iter()
            .map(|name| {
                entry(
                    name,
                    Some(1.0 + 99.0 * next()),
                    1.0,
                    10f64.powf(-5.0 * next()),
                )
            })
            .collect();
        let ceiling = ceiling("lens", &entries).unwrap();
        for metric in [Metric::Mse, Metric::Flip] {
            if let Some(least) = verdict("lens", &entries, metric).unwrap().least_speedup {
                assert!(
                    least <= ceiling.ratio * (1.0 + 1e-12),
                    "{least} > {ceiling:?}"
                );
                compared += 1;
            }
        }
    }
    assert!(compared > 500, "{compared} verdicts with a least speed-up");

    let rt_only: Vec<CompareEntry> = family().into_iter().take(3).collect();
    assert!(ceiling("lens", &rt_only).is_none());
    assert!(ceiling("lens", &family()[3..]).is_none());
}

/// The report says each level, what only one family reaches, and the least speed-up.
#[test]
fn the_markdown_states_every_level() {
    let entries = family();
    let verdicts = vec![verdict("lens", &entries, Metric::Mse).unwrap()];
    let report = CompareReport {
        run: Run {
            machine: crate::bench::Machine {
                adapter: "a".into(),
                driver: "d".into(),
                cpu: "c".into(),
                cpus: 2,
                date: "2026-11-23".into(),
            },
            scene: "s".into(),
            triangles: 1,
            size: "8x8".into(),
        },
        pose: "p".into(),
        reference_spp: 256,
        frames: 1,
        method_note: COMPARE_NOTE,
        entries,
        verdicts,
        ceilings: vec![ceiling("lens", &family()).unwrap()],
        skipped: Vec::new(),
    };
    let md = report.markdown();
    assert!(
        md.contains("| lens | rt@4spp | 40.0 | 4.00 k | 10000 | 1.00e-3 |"),
        "{md}"
    );
    assert!(md.contains("- lens, MSE (least: 2.00x slower): at cube-rt@64's MSE 8.00e-3 (5.00 ms) RT needs 10.0 ms: 2.00x slower; at cube-rt@128's MSE 2.00e-3 (40.0 ms) RT needs 20.0 ms: 2.00x faster"), "{md}");
    assert!(md.contains("only RT reaches below the cube maps' best, down to 2.50e-4 (rt@16spp)"));
    // What a texel costs: 40 ms over 128² of them; a frame of no samples has no cost a sample.
    assert!(
        md.contains("| lens | cube-rt@128 | 40.0 | 16.4 k | 2441 | 2.00e-3 |"),
        "{md}"
    );
    assert_eq!(per_sample_ns(1.0, 0.0), "—");
    assert!(
        md.contains("- lens: cube-rt@64 (5.00 ms) over rt@1spp (10.0 ms): at most 2.00x slower"),
        "{md}"
    );
    assert!(md.contains("- lens, MSE (least: 4.10x fewer): at cube-rt@64's MSE 8.00e-3 (4.10 k texels) RT needs 1.00 k rays: 4.10x fewer; at cube-rt@128's MSE 2.00e-3 (16.4 k texels) RT needs 2.00 k rays: 8.19x fewer"), "{md}");
}
