//! Moving objects in datasets: a keyed box slides past a still camera.

use super::*;

/// The scene file of [`flow_follows_moving_objects`], its box keyed as given or held at `x`.
fn sliding_scene(keys: Option<f64>) -> String {
    let place = match keys {
        None => "[[mesh.key]]\ntime = 0.0\ntranslation = [-1.0, 0.0, 5.0]\n\
                 [[mesh.key]]\ntime = 1.0\ntranslation = [1.0, 0.0, 5.0]\n"
            .to_string(),
        Some(x) => format!("translation = [{x}, 0.0, 5.0]\n"),
    };
    format!(
        "sky = [0.3, 0.4, 0.5]\n[[mesh]]\nshape = \"box\"\nscale = [40.0, 40.0, 0.1]\n\
         translation = [0.0, 0.0, 12.0]\n[[mesh]]\nshape = \"box\"\nscale = [2.5, 2.5, 0.2]\n\
         {place}[[light]]\ntype = \"sun\"\ndirection = [0.2, 0.3, 1.0]\n\
         irradiance = [1.0, 1.0, 1.0]\n"
    )
}

/// `fisheye render --time 0.3` renders the keyed box where its keys put it then: the ids of
/// a scene file with the box fixed at x = -0.4 (but for edge pixels: one is an instance in
/// f32, the other world triangles), and not those of time 0.
#[test]
fn render_at_a_time_places_keyed_meshes() {
    let dir = temp_dir("render-time");
    let keyed = dir.join("keyed.toml");
    std::fs::write(&keyed, sliding_scene(None)).unwrap();
    let fixed = dir.join("fixed.toml");
    std::fs::write(&fixed, sliding_scene(Some(-0.4))).unwrap();
    let ids = |scene: &Path, time: &str| -> Vec<u32> {
        let out = dir.join(format!(
            "{}-{time}.png",
            scene.file_stem().unwrap().to_string_lossy()
        ));
        succeed(
            fisheye()
                .args([
                    "render",
                    "--lens",
                    "rectilinear:f=1.2",
                    "--size",
                    "32x24",
                    "--spp",
                    "1",
                ])
                .args([
                    "--camera",
                    "0,0,0:0,0,1",
                    "--outputs",
                    "id",
                    "--time",
                    time,
                    "-o",
                ])
                .arg(&out)
                .arg(scene),
        );
        let bytes = std::fs::read(out.with_extension("id.npy")).unwrap();
        npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap()
    };
    let (moved, held, start) = (ids(&keyed, "0.3"), ids(&fixed, "0"), ids(&keyed, "0"));
    let differ = moved.iter().zip(&held).filter(|(a, b)| a != b).count();
    assert!(differ <= 3, "{differ} pixels differ");
    assert!(moved.iter().zip(&start).filter(|(a, b)| a != b).count() > 10);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene file's box keyed to slide 2 m a second along x, 5 m in front of a still pinhole
/// camera, against a still backdrop at 12 m: rendered at 5 Hz (globally and through a rolling
/// shutter), each box pixel's forward flow is where its hit, moved 0.4 m along x, lands
/// through the lens (to 1e-3 px; a rolling shutter reads a point moving along x on the same
/// line, so its landing is a frame later either way), its scene flow is (0.4, 0, 0); the
/// backdrop's flow is zero, and it is valid except where the box covers it in the next frame
/// (all but edge pixels). Two shards write the bytes one process writes.
#[test]
fn flow_follows_moving_objects() {
    let dir = temp_dir("objects");
    let scene = dir.join("sliding.toml");
    std::fs::write(&scene, sliding_scene(None)).unwrap();
    let trajectory = dir.join("still.tum");
    std::fs::write(&trajectory, "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n").unwrap();
    let spec = "rectilinear:f=1.2";
    let camera = fisheye_rt::lens::LensCamera::new(
        fisheye_rt::lens::parse_spec(spec).unwrap(),
        fisheye_rt::lens::ImageSize::new(32, 24).unwrap(),
    );
    for delay in ["0", "0.002"] {
        let out = dir.join(format!("set-{delay}"));
        let render = |out: &Path, shard: &str| {
            succeed(
                fisheye()
                    .args([
                        "dataset", "render", "--lens", spec, "--size", "32x24", "--spp", "1",
                    ])
                    .args(["--frame-rate", "5", "--line-delay", delay, "--shard", shard])
                    .args(["--outputs", "flow,scene-flow,range,id"])
                    .arg("--trajectory")
                    .arg(&trajectory)
                    .arg("-o")
                    .arg(out)
                    .arg(&scene),
            );
        };
        render(&out, "0/1");
        if delay != "0" {
            // Shards place the objects at each of their frames' times as one process does.
            let sharded = dir.join("sharded");
            render(&sharded, "0/2");
            render(&sharded, "1/2");
            succeed(fisheye().args(["dataset", "merge"]).arg(&sharded));
            assert_eq!(files(&out), files(&sharded));
        }
        let read = |stem: &str, name: &str| -> Vec<u8> {
            std::fs::read(out.join("cam0").join(format!("{stem}.{name}.npy"))).unwrap()
        };
        let floats = |stem: &str, name: &str| -> Vec<f32> {
            npyz::NpyFile::new(&read(stem, name)[..])
                .unwrap()
                .into_vec()
                .unwrap()
        };
        let (stem, next) = ("000001_0.200000", "000002_0.400000");
        let (flow, moved, range) = (
            floats(stem, "flow"),
            floats(stem, "scene_flow"),
            floats(stem, "range"),
        );
        let valid: Vec<u8> = npyz::NpyFile::new(&read(stem, "flow_valid")[..])
            .unwrap()
            .into_vec()
            .unwrap();
        let ids = |stem: &str| -> Vec<u32> {
            npyz::NpyFile::new(&read(stem, "id")[..])
                .unwrap()
                .into_vec()
                .unwrap()
        };
        let (here, there) = (ids(stem), ids(next));
        // The backdrop's 12 world triangles first, then the box's.
        let on_box = |id: u32| (12..24).contains(&id);
        let (mut box_pixels, mut covered, mut mismatched) = (0, 0, 0);
        for y in 0..24u32 {
            for x in 0..32u32 {
                let i = (y * 32 + x) as usize;
                let d = camera.pixel_direction(x, y).unwrap();
                let hit = d * f64::from(range[i]);
                let got = glam::DVec2::new(flow[2 * i].into(), flow[2 * i + 1].into());
                let scene_flow = DVec3::new(
                    moved[3 * i].into(),
                    moved[3 * i + 1].into(),
                    moved[3 * i + 2].into(),
                );
                let centre = glam::DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                if on_box(here[i]) {
                    box_pixels += 1;
                    let shift = DVec3::new(0.4, 0.0, 0.0);
                    assert!(
                        (scene_flow - shift).length() < 1e-4,
                        "{delay}: pixel {i}: {scene_flow}"
                    );
                    if let Some(p) = camera.project(hit + shift) {
                        if got.x.is_nan() {
                            continue; // lands outside the image
                        }
                        let wanted = p - centre;
                        assert!(
                            (got - wanted).length() < 1e-3,
                            "{delay}: pixel {i}: {got}, not {wanted}"
                        );
                    }
                } else {
                    assert!(
                        got.length() < 1e-4,
                        "{delay}: backdrop pixel {i} moves by {got}"
                    );
                    assert!(
                        scene_flow.length() < 1e-4,
                        "{delay}: pixel {i}: {scene_flow}"
                    );
                    let hidden = on_box(there[i]);
                    covered += usize::from(hidden);
                    if (valid[i] == 0) != hidden {
                        mismatched += 1;
                    }
                }
            }
        }
        assert!(
            box_pixels > 30 && covered > 5,
            "{delay}: {box_pixels} box pixels, {covered} covered"
        );
        assert!(
            mismatched <= 4,
            "{delay}: {mismatched} backdrop pixels' validity is not the next frame's cover"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
