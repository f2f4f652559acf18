//! A glTF file's animations, read into each node's keys ([`NodeKeys`]): every animation plays
//! at once from scene time 0 (a file may hold several; they move different nodes, as
//! exporters write one per object). A channel of morph-target weights is left out with a
//! warning; two channels keying the same property of one node keep the first, warned.

use std::collections::{BTreeSet, HashMap};

use glam::{DQuat, DVec3, Vec3};

use crate::scene::animation::{Interpolation, Keys};

/// The keys of one node's translation, rotation and scale (each where a channel moves it).
#[derive(Clone, Debug, Default)]
pub(super) struct NodeKeys {
    pub translation: Option<Keys<DVec3>>,
    pub rotation: Option<Keys<DQuat>>,
    pub scale: Option<Keys<DVec3>>,
}

/// Every channel of every animation in `document`, by node index; `ignored` collects what is
/// left out. Errors (a message without the file's name) where a sampler's accessors are of a
/// type the spec does not allow, reach beyond their buffers, or key badly.
pub(super) fn read(
    document: &gltf::Document,
    buffers: &[Vec<u8>],
    ignored: &mut BTreeSet<String>,
) -> Result<HashMap<usize, NodeKeys>, String> {
    use gltf::accessor::{DataType as D, Dimensions as N};
    use gltf::animation::Property;
    use gltf::animation::util::ReadOutputs;
    let mut nodes: HashMap<usize, NodeKeys> = HashMap::new();
    for animation in document.animations() {
        for channel in animation.channels() {
            let what = format!(
                "animations[{}].channels[{}]",
                animation.index(),
                channel.index()
            );
            let property = channel.target().property();
            let (types, dimensions): (&[D], N) = match property {
                Property::Translation | Property::Scale => (&[D::F32], N::Vec3),
                Property::Rotation => (&[D::F32, D::I8, D::U8, D::I16, D::U16], N::Vec4),
                Property::MorphTargetWeights => {
                    ignored.insert("morph target animations".into());
                    continue;
                }
            };
            let sampler = channel.sampler();
            let (input, output) = (sampler.input(), sampler.output());
            for (accessor, name, types, dimensions) in [
                (&input, "input", &[D::F32][..], N::Scalar),
                (&output, "output", types, dimensions),
            ] {
                if !types.contains(&accessor.data_type()) || accessor.dimensions() != dimensions {
                    return Err(format!(
                        "{what}: its sampler's {name} is accessors[{}], of {:?} {:?}; it must \
                         be {dimensions:?} of {types:?}",
                        accessor.index(),
                        accessor.dimensions(),
                        accessor.data_type()
                    ));
                }
            }
            let beyond = |a: &gltf::Accessor| {
                format!("{what}: accessors[{}] reaches beyond its buffer", a.index())
            };
            let reader = channel.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let times: Vec<f64> = reader
                .read_inputs()
                .ok_or_else(|| beyond(&input))?
                .map(f64::from)
                .collect();
            let interpolation = match sampler.interpolation() {
                gltf::animation::Interpolation::Step => Interpolation::Step,
                gltf::animation::Interpolation::Linear => Interpolation::Linear,
                gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
            };
            let keys = NodeKeys::default();
            let node = channel.target().node().index();
            let entry = nodes.entry(node).or_insert(keys);
            let taken = match property {
                Property::Translation => entry.translation.is_some(),
                Property::Rotation => entry.rotation.is_some(),
                _ => entry.scale.is_some(),
            };
            if taken {
                ignored.insert(format!(
                    "channels keying a property of a node another channel keyed first ({what})"
                ));
                continue;
            }
            let outputs = reader.read_outputs().ok_or_else(|| beyond(&output))?;
            let vectors = |values: Vec<[f32; 3]>| -> Vec<DVec3> {
                values
                    .into_iter()
                    .map(|v| Vec3::from(v).as_dvec3())
                    .collect()
            };
            let check = |keys: &dyn Fn() -> Result<(), String>| {
                keys().map_err(|e| format!("{what} of nodes[{node}]: {e}"))
            };
            match outputs {
                ReadOutputs::Translations(v) | ReadOutputs::Scales(v) => {
                    let keys = Keys {
                        times,
                        values: vectors(v.collect()),
                        interpolation,
                    };
                    check(&|| keys.check())?;
                    match property {
                        Property::Translation => entry.translation = Some(keys),
                        _ => entry.scale = Some(keys),
                    }
                }
                ReadOutputs::Rotations(r) => {
                    let mut values: Vec<DQuat> = r
                        .into_f32()
                        .map(|[x, y, z, w]| {
                            DQuat::from_xyzw(x.into(), y.into(), z.into(), w.into())
                        })
                        .collect();
                    // Spline tangents are not unit quaternions; key values must be.
                    let stride = if interpolation == Interpolation::CubicSpline {
                        3
                    } else {
                        1
                    };
                    if let Some(k) = (0..values.len() / stride).find(|&k| {
                        let q = values[k * stride + stride / 2];
                        !(q.is_finite() && q.length_squared() > 0.0)
                    }) {
                        return Err(format!(
                            "{what} of nodes[{node}]: key {k}'s rotation is not a rotation"
                        ));
                    }
                    // Slerp takes unit quaternions; the spec asks for them, files round.
                    for k in 0..values.len() / stride {
                        let q = &mut values[k * stride + stride / 2];
                        *q = q.normalize();
                    }
                    let keys = Keys {
                        times,
                        values,
                        interpolation,
                    };
                    check(&|| keys.check())?;
                    entry.rotation = Some(keys);
                }
                ReadOutputs::MorphTargetWeights(_) => unreachable!("left out above"),
            }
        }
    }
    Ok(nodes)
}
