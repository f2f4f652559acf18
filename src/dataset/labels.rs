//! Instance and semantic segmentation through the lens ([`Label`]): each pixel's object and
//! class, from its primary hit's scene triangle and the scene's labelled objects
//! ([`crate::scene::Object`]), stable across frames; and the label map that names them
//! (`labels.json`).

use serde_json::json;

use crate::scene::{NO_OBJECT, Scene};
use crate::trace::Values;

/// The label map's file in a dataset's folder.
pub const LABEL_MAP: &str = "labels.json";

/// A segmentation output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Label {
    /// The object (an index into the label map's `instances`) of each pixel's hit.
    Instance,
    /// Its class (an index into the label map's `classes`).
    Semantic,
}

impl Label {
    /// The output's name on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            Self::Instance => "instance",
            Self::Semantic => "semantic",
        }
    }

    /// The array of a frame whose hits are scene triangles `ids`: u32, [`NO_OBJECT`] where
    /// the pixel sees nothing.
    pub fn values(self, scene: &Scene, ids: &[u32]) -> Values {
        let objects = scene.objects_of(ids);
        match self {
            Self::Instance => Values::U32(objects),
            Self::Semantic => {
                let (_, class_of) = scene.classes();
                Values::U32(
                    objects
                        .into_iter()
                        .map(|o| match o {
                            NO_OBJECT => NO_OBJECT,
                            o => class_of[o as usize],
                        })
                        .collect(),
                )
            }
        }
    }
}

/// The label map of `scene`: every object with its name and class, every class, and the
/// value that marks a pixel seeing nothing.
pub fn label_map(scene: &Scene) -> String {
    let (classes, class_of) = scene.classes();
    let map = json!({
        "instances": scene.objects.iter().zip(&class_of).enumerate().map(|(i, (o, &c))| json!({
            "id": i,
            "name": o.name,
            "class": o.class,
            "class_id": c,
        })).collect::<Vec<_>>(),
        "classes": classes.iter().enumerate().map(|(i, name)| json!({"id": i, "name": name}))
            .collect::<Vec<_>>(),
        "none": NO_OBJECT,
        "sources": "a glTF node's name and its extras' class (or its mesh's name); an OBJ \
                    object's or group's name; a scene file mesh's name and class; a \
                    material's name where nothing names the triangle; each placement of an \
                    instanced mesh is an instance of its own",
    });
    serde_json::to_string_pretty(&map).expect("JSON values serialise") + "\n"
}
