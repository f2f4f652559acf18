//! Animated glTF nodes: instances are where glTF's samplers put them at each scene time.

use super::*;
use glam::DAffine3;

/// A triangle mesh placed by five nodes, each keyed differently: translation linear, rotation
/// linear (slerp), scale step, translation by a cubic spline with tangents, and a child of the
/// first. At each time the instance's placement is the one computed by hand from glTF 2.0's
/// Appendix C (held at the end keys outside them).
#[test]
fn animated_nodes_are_where_the_samplers_put_them() {
    let dir = temp_dir("animated");
    let mut doc = Doc::default();
    let positions = doc.positions(&TRIANGLE);
    let mesh = doc.mesh(vec![json!({"attributes": {"POSITION": positions}})]);
    let times = doc.floats(&[0.0, 2.0], "SCALAR", 2);
    let unit_times = doc.floats(&[0.0, 1.0], "SCALAR", 2);
    let step_times = doc.floats(&[0.0, 1.0, 2.0], "SCALAR", 3);
    let moves = doc.floats(&[0.0, 0.0, 0.0, 4.0, 0.0, 0.0], "VEC3", 2);
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let turns = doc.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, s, 0.0, s], "VEC4", 2);
    let scales = doc.floats(&[1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 3.0, 3.0, 3.0], "VEC3", 3);
    // Cubic spline: (in-tangent, value, out-tangent) per key.
    #[rustfmt::skip]
    let spline = doc.floats(&[
        0.0, 0.0, 0.0,  0.0, 0.0, 0.0,  3.0, 0.0, 0.0,
        0.0, 0.0, 0.0,  1.0, 0.0, 0.0,  0.0, 0.0, 0.0,
    ], "VEC3", 6);
    let child = doc.node(json!({"mesh": mesh, "translation": [0.0, 1.0, 0.0]}));
    let nodes = [
        doc.node(json!({"mesh": mesh, "children": [child]})),
        doc.node(json!({"mesh": mesh, "translation": [0.0, 0.0, -5.0]})),
        doc.node(json!({"mesh": mesh})),
        doc.node(json!({"mesh": mesh})),
    ];
    let sampler = |input: usize, output: usize, interpolation: &str| json!({"input": input, "output": output, "interpolation": interpolation});
    doc.extra.insert(
        "animations".into(),
        json!([
            {"samplers": [sampler(times, moves, "LINEAR"), sampler(unit_times, turns, "LINEAR")],
             "channels": [
                {"sampler": 0, "target": {"node": nodes[0], "path": "translation"}},
                {"sampler": 1, "target": {"node": nodes[1], "path": "rotation"}}]},
            {"samplers": [sampler(step_times, scales, "STEP"),
                          sampler(unit_times, spline, "CUBICSPLINE")],
             "channels": [
                {"sampler": 0, "target": {"node": nodes[2], "path": "scale"}},
                {"sampler": 1, "target": {"node": nodes[3], "path": "translation"}}]},
        ]),
    );
    let path = doc.write_glb(&dir, "animated", &nodes);
    let loaded = load_gltf(&path, None).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        loaded.warnings.iter().all(|w| !w.contains("animation")),
        "{:?}",
        loaded.warnings
    );
    let scene = loaded.scene;
    // Nodes in traversal order: the first, its child, then the others.
    assert_eq!(scene.instances.len(), 5);
    assert!(scene.moves());
    let x = |x: f64| DAffine3::from_translation(DVec3::new(x, 0.0, 0.0));
    let about_y = |degrees: f64| {
        DAffine3::from_translation(DVec3::new(0.0, 0.0, -5.0))
            * DAffine3::from_quat(DQuat::from_rotation_y(degrees.to_radians()))
    };
    let scaled = |s: f64| DAffine3::from_scale(DVec3::splat(s));
    let up = DAffine3::from_translation(DVec3::Y);
    // (time, the five placements), by hand.
    let expected = [
        (-1.0, [x(0.0), up, about_y(0.0), scaled(1.0), x(0.0)]),
        (
            0.5,
            [x(1.0), x(1.0) * up, about_y(45.0), scaled(1.0), x(0.875)],
        ),
        (
            1.0,
            [x(2.0), x(2.0) * up, about_y(90.0), scaled(2.0), x(1.0)],
        ),
        (
            1.999,
            [x(3.998), x(3.998) * up, about_y(90.0), scaled(2.0), x(1.0)],
        ),
        (
            7.0,
            [x(4.0), x(4.0) * up, about_y(90.0), scaled(3.0), x(1.0)],
        ),
    ];
    for (t, placements) in expected {
        let posed = scene.at(t);
        for (k, (instance, want)) in posed.instances.iter().zip(placements).enumerate() {
            assert!(
                instance.transform.abs_diff_eq(want, 1e-6),
                "t = {t}, instance {k}: {:?}, not {want:?}",
                instance.transform
            );
        }
    }
    // Time 0 is the scene as loaded.
    let still: Vec<DAffine3> = scene.instances.iter().map(|i| i.transform).collect();
    assert_eq!(scene.placements_at(0.0), still);
    assert!(!scene.at(0.5).moves());
}

/// Bad animations name the channel and what is wrong: keys out of order, too few values, a
/// translation keyed by a VEC2 accessor, and a keyed node given by a matrix.
#[test]
fn bad_animations_name_the_channel() {
    let dir = temp_dir("bad-animation");
    // (name, key times, values, their type, whether the node is a matrix, the message).
    type Case<'a> = (&'a str, &'a [f32], &'a [f32], &'a str, bool, &'a str);
    let cases: [Case; 4] = [
        (
            "unordered",
            &[1.0, 0.5],
            &[0.0; 6],
            "VEC3",
            false,
            "key times must increase",
        ),
        (
            "short",
            &[0.0, 1.0, 2.0],
            &[0.0; 6],
            "VEC3",
            false,
            "3 keys need 3 values",
        ),
        (
            "vec2",
            &[0.0, 1.0],
            &[0.0; 4],
            "VEC2",
            false,
            "must be Vec3",
        ),
        ("matrix", &[0.0, 1.0], &[0.0; 6], "VEC3", true, "matrix"),
    ];
    for (name, times, values, kind, matrix, wanted) in cases {
        let mut doc = Doc::default();
        let positions = doc.positions(&TRIANGLE);
        let mesh = doc.mesh(vec![json!({"attributes": {"POSITION": positions}})]);
        let input = doc.floats(times, "SCALAR", times.len());
        let per = if kind == "VEC2" { 2 } else { 3 };
        let output = doc.floats(values, kind, values.len() / per);
        let node = if matrix {
            doc.node(json!({"mesh": mesh, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}))
        } else {
            doc.node(json!({"mesh": mesh}))
        };
        doc.extra.insert(
            "animations".into(),
            json!([{"samplers": [{"input": input, "output": output}],
                "channels": [{"sampler": 0, "target": {"node": node, "path": "translation"}}]}]),
        );
        let path = doc.write_embedded(&dir, name, &[node]);
        let message = load_gltf(&path, None)
            .err()
            .unwrap_or_else(|| panic!("{name}: loaded"))
            .to_string();
        assert!(
            message.contains(wanted) && message.contains(&format!("{name}.gltf")),
            "{name}: {message}"
        );
        if !matrix {
            assert!(message.contains("animations[0].channels[0]"), "{message}");
        }
    }
}

/// Rendered on the GPU at 0.5 s, a cube keyed to slide (linear) and turn (slerp) over 2 s is
/// where a still copy of the file with the node's translation and rotation worked out by hand
/// puts it: the same ids but for pixels on id edges (an instance's f32 maps against world
/// triangles), and not those of time 0.
#[test]
fn an_animated_gltf_renders_where_a_still_copy_at_that_time_does() {
    use fisheye_rt::scene::Camera;
    let dir = temp_dir("animated-render");
    let write = |cube_node: Value, animated: bool| {
        let mut doc = Doc::default();
        let (cube, floor) = doc.cube_and_floor(None);
        let mut roots = vec![doc.node(json!({"mesh": floor}))];
        let mut node = cube_node;
        node["mesh"] = json!(cube);
        roots.push(doc.node(node));
        if animated {
            let times = doc.floats(&[0.0, 2.0], "SCALAR", 2);
            let moves = doc.floats(&[-2.0, 0.0, -5.0, 2.0, 0.0, -5.0], "VEC3", 2);
            let s = std::f32::consts::FRAC_1_SQRT_2;
            let turns = doc.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, s, 0.0, s], "VEC4", 2);
            doc.extra.insert(
                "animations".into(),
                json!([{"samplers": [{"input": times, "output": moves},
                                     {"input": times, "output": turns}],
                    "channels": [
                        {"sampler": 0, "target": {"node": roots[1], "path": "translation"}},
                        {"sampler": 1, "target": {"node": roots[1], "path": "rotation"}}]}]),
            );
        }
        let name = if animated { "animated" } else { "still" };
        let mut scene = load_gltf(&doc.write_glb(&dir, name, &roots), None)
            .unwrap_or_else(|e| panic!("{e}"))
            .scene;
        scene.set_camera(Camera {
            position: DVec3::new(0.0, 2.0, 1.0),
            look_at: DVec3::new(0.0, 0.0, -5.0),
            up: DVec3::Y,
        });
        scene
    };
    let animated = write(json!({}), true);
    // At 0.5 s: a quarter of the way, x = -1, turned 22.5° about y.
    let turn = DQuat::from_rotation_y(22.5f64.to_radians());
    let still = write(
        json!({"translation": [-1.0, 0.0, -5.0],
               "rotation": [turn.x, turn.y, turn.z, turn.w]}),
        false,
    );
    let cam = common::camera("equidistant:f=0.5,fov=180", 96, 72);
    let options = RenderOptions::default();
    let ids = |scene: &fisheye_rt::scene::Scene| {
        render(common::ctx(), scene, &cam, &options).unwrap().ids
    };
    let (moved, held, start) = (ids(&animated.at(0.5)), ids(&still), ids(&animated.at(0.0)));
    let mut edges = 0;
    for i in 0..moved.len() {
        if moved[i] != held[i] {
            assert!(common::on_id_edge(&held, cam.size, i), "pixel {i}");
            edges += 1;
        }
    }
    assert!(edges <= 4, "{edges} pixels differ");
    assert!(moved.iter().zip(&start).filter(|(a, b)| a != b).count() > 20);
}
