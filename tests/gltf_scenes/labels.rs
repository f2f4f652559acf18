//! Labels for the instance and semantic outputs, from glTF names and extras.

use super::*;

/// Three nodes place one mesh named "crate", one of them with `extras.class`, one unnamed,
/// and a floor node carries `extras.semantic`: each node is an object of its own, named by
/// the node (`nodes[N]` unnamed), classed by its extras, else by its mesh's name. Rendered, each
/// pixel's object is the one whose triangles hold its hit's id (the instanced scene and its
/// flattened copy agree), all four are seen, and the classes are the three named.
#[test]
fn gltf_nodes_name_objects_and_extras_class_them() {
    use fisheye_rt::scene::{Camera, NO_OBJECT};
    use fisheye_rt::trace::NO_HIT;
    let dir = temp_dir("labels");
    let mut doc = Doc::default();
    let (cube, floor) = doc.cube_and_floor(None);
    doc.meshes[cube]["name"] = json!("crate");
    let roots = vec![
        doc.node(json!({"mesh": floor, "name": "floor", "extras": {"semantic": "ground"}})),
        doc.node(
            json!({"mesh": cube, "name": "left", "translation": [-2.0, 0.0, -4.0],
            "extras": {"class": "box"}}),
        ),
        doc.node(json!({"mesh": cube, "name": "middle", "translation": [0.5, 0.0, -5.0]})),
        doc.node(json!({"mesh": cube, "translation": [2.5, 0.0, -4.0]})),
    ];
    let path = doc.write_glb(&dir, "labelled", &roots);
    let mut scene = load_gltf(&path, None)
        .unwrap_or_else(|e| panic!("{e}"))
        .scene;
    let named = |o: u32| {
        let o = &scene.objects[o as usize];
        (o.name.clone(), o.class.clone())
    };
    let wanted = [
        ("floor", "ground"),
        ("left", "box"),
        ("middle", "crate"),
        ("nodes[3]", "crate"),
    ];
    let floor_object = scene.object_of[0];
    assert_eq!(named(floor_object), ("floor".into(), "ground".into()));
    for (instance, (name, class)) in scene.instances.iter().zip(&wanted[1..]) {
        assert_eq!(
            named(instance.object),
            (name.to_string(), class.to_string())
        );
    }
    let (classes, _) = scene.classes();
    for class in ["ground", "box", "crate"] {
        assert!(classes.iter().any(|c| c == class), "{classes:?}");
    }
    scene.set_camera(Camera {
        position: DVec3::new(0.0, 2.5, 3.0),
        look_at: DVec3::new(0.0, 0.5, -4.0),
        up: DVec3::Y,
    });
    let cam = common::camera("equidistant:f=0.5,fov=180", 128, 96);
    let out = render(common::ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    let objects = scene.objects_of(&out.ids);
    let flat = scene.flattened(usize::MAX).unwrap();
    assert_eq!(flat.objects_of(&out.ids), objects);
    let mut seen = std::collections::BTreeSet::new();
    for (&id, &object) in out.ids.iter().zip(&objects) {
        if id == NO_HIT {
            assert_eq!(object, NO_OBJECT);
            continue;
        }
        // World triangles 0 and 1 are the floor's; instance k's are 2 + 12k onwards.
        let wanted = match id {
            0 | 1 => floor_object,
            id => scene.instances[(id as usize - 2) / 12].object,
        };
        assert_eq!(object, wanted, "id {id}");
        seen.insert(object);
    }
    assert_eq!(seen.len(), 4, "objects seen: {seen:?}");
}
