//! WGSL assembly: every shader file is embedded, `#import NAME` lines pull in shared files
//! (each once, dependencies first), and constants defined once in Rust ([`crate::shared`]) are
//! prepended as WGSL `const` lines. Pipeline specialisations (lens model, direction formula) are WGSL
//! `override`s, set per pipeline, or files swapped in for others when a pipeline is composed
//! (the direction table's `primary_table` for `primary`). One module is generated rather than
//! embedded:
//! `scene_arrays`, the scene's arrays split across as many storage bindings as the scene
//! needs ([`crate::split`]), so kernels that read a scene are composed for it
//! ([`compose_for`]).

use std::fmt::Write;

use crate::shared::{wgsl_constants, wgsl_faces, wgsl_float_constants, wgsl_nested_samples};
use crate::split::SceneArrays;

/// The name `#import` gives the generated module of the scene's arrays.
const SCENE_ARRAYS: &str = "scene_arrays";

/// Every WGSL file of the project, by name (its file stem under `wgsl/`).
pub const FILES: [(&str, &str); 38] = [
    ("math", include_str!("../wgsl/math.wgsl")),
    ("quaternion", include_str!("../wgsl/quaternion.wgsl")),
    ("calibrated", include_str!("../wgsl/calibrated.wgsl")),
    ("triangles", include_str!("../wgsl/triangles.wgsl")),
    ("bvh", include_str!("../wgsl/bvh.wgsl")),
    ("bvh_rq", include_str!("../wgsl/bvh_rq.wgsl")),
    ("surface", include_str!("../wgsl/surface.wgsl")),
    ("shade", include_str!("../wgsl/shade.wgsl")),
    ("trace", include_str!("../wgsl/trace.wgsl")),
    ("trace_rq", include_str!("../wgsl/trace_rq.wgsl")),
    ("pixel", include_str!("../wgsl/pixel.wgsl")),
    ("frame", include_str!("../wgsl/frame.wgsl")),
    ("colour", include_str!("../wgsl/colour.wgsl")),
    ("adaptive", include_str!("../wgsl/adaptive.wgsl")),
    ("interpolate", include_str!("../wgsl/interpolate.wgsl")),
    (
        "adaptive_lists",
        include_str!("../wgsl/adaptive_lists.wgsl"),
    ),
    (
        "adaptive_samples",
        include_str!("../wgsl/adaptive_samples.wgsl"),
    ),
    ("adaptive_rq", include_str!("../wgsl/adaptive_rq.wgsl")),
    ("adaptive_args", include_str!("../wgsl/adaptive_args.wgsl")),
    ("tent", include_str!("../wgsl/tent.wgsl")),
    ("cast", include_str!("../wgsl/cast.wgsl")),
    ("lens", include_str!("../wgsl/lens.wgsl")),
    ("glass", include_str!("../wgsl/glass.wgsl")),
    ("glass_probe", include_str!("../wgsl/glass_probe.wgsl")),
    ("primary", include_str!("../wgsl/primary.wgsl")),
    ("primary_table", include_str!("../wgsl/primary_table.wgsl")),
    ("lens_rays", include_str!("../wgsl/lens_rays.wgsl")),
    ("lens_points", include_str!("../wgsl/lens_points.wgsl")),
    ("lens_demo", include_str!("../wgsl/lens_demo.wgsl")),
    ("trig_probe", include_str!("../wgsl/trig_probe.wgsl")),
    ("cube", include_str!("../wgsl/cube.wgsl")),
    ("cube_probe", include_str!("../wgsl/cube_probe.wgsl")),
    ("cube_sample", include_str!("../wgsl/cube_sample.wgsl")),
    ("cube_store", include_str!("../wgsl/cube_store.wgsl")),
    ("present", include_str!("../wgsl/present.wgsl")),
    ("sampling", include_str!("../wgsl/sampling.wgsl")),
    ("raster", include_str!("../wgsl/raster.wgsl")),
    (
        "raster_multiview",
        include_str!("../wgsl/raster_multiview.wgsl"),
    ),
];

fn file(name: &str) -> &'static str {
    FILES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
        .unwrap_or_else(|| panic!("#import {name}: no such file in wgsl/ (see shader::FILES)"))
}

/// What composing a module has gathered: the files already appended, `#swap`s in force, and
/// the `enable` directives (which WGSL wants before any declaration).
#[derive(Default)]
struct Composition {
    arrays: SceneArrays,
    seen: Vec<String>,
    swaps: Vec<(String, String)>,
    enables: Vec<String>,
    body: String,
}

impl Composition {
    fn append(&mut self, name: &str) {
        let name = self
            .swaps
            .iter()
            .find(|(from, _)| from == name)
            .map_or(name, |(_, to)| to.as_str())
            .to_string();
        if self.seen.contains(&name) {
            return;
        }
        self.seen.push(name.clone());
        if name == SCENE_ARRAYS {
            writeln!(self.body, "// ---- {SCENE_ARRAYS}").unwrap();
            self.body.push_str(&self.arrays.wgsl());
            return;
        }
        let text = file(&name);
        for line in text.lines().map(str::trim) {
            if let Some((from, to)) = line.strip_prefix("#swap ").and_then(|s| s.split_once(' ')) {
                self.swaps.push((from.trim().into(), to.trim().into()));
            } else if let Some(dep) = line.strip_prefix("#import ") {
                self.append(dep.trim());
            } else if line.starts_with("enable ") && !self.enables.iter().any(|e| e == line) {
                self.enables.push(line.into());
            }
        }
        writeln!(self.body, "// ---- wgsl/{name}.wgsl").unwrap();
        for line in text.lines() {
            let directive = line.trim();
            if !["#import ", "#swap ", "enable "]
                .iter()
                .any(|d| directive.starts_with(d))
            {
                self.body.push_str(line);
                self.body.push('\n');
            }
        }
    }
}

/// The complete WGSL source of the module whose entry file is `entry`: its `enable`
/// directives, the constants, then every file it imports (dependencies first, each once; a
/// `#swap A B` line makes later `#import A`s pull in `B` instead), then the entry file; a
/// scene's arrays each in one binding.
pub fn compose(entry: &str) -> String {
    compose_for(entry, &SceneArrays::default(), &[])
}

/// As [`compose`], for a scene whose arrays are split as `arrays` says, with `swaps` in force
/// from the start (`(A, B)` as a `#swap A B` line would).
pub fn compose_for(entry: &str, arrays: &SceneArrays, swaps: &[(&str, &str)]) -> String {
    let mut c = Composition {
        arrays: *arrays,
        swaps: swaps
            .iter()
            .map(|&(from, to)| (from.into(), to.into()))
            .collect(),
        ..Default::default()
    };
    c.append(entry);
    let mut out = String::new();
    for enable in &c.enables {
        writeln!(out, "{enable}").unwrap();
    }
    out.push_str("// ---- constants from fisheye_rt::shared::wgsl_constants()\n");
    for (name, value) in wgsl_constants() {
        writeln!(out, "const {name}: u32 = {value}u;").unwrap();
    }
    for (name, value) in wgsl_float_constants() {
        // `{:?}` writes a float that reads back exactly, always with a point or exponent.
        writeln!(out, "const {name}: f32 = {value:?};").unwrap();
    }
    out.push_str(&wgsl_faces());
    out.push_str(&wgsl_nested_samples());
    out.push_str(&c.body);
    out
}

/// Creates the shader module for `entry`, labelled `fisheye.<entry>`, for a scene whose
/// arrays are split as `arrays` says (the default for kernels that read no scene).
pub fn module(device: &wgpu::Device, entry: &str, arrays: &SceneArrays) -> wgpu::ShaderModule {
    module_from(device, entry, compose_for(entry, arrays, &[]))
}

fn module_from(device: &wgpu::Device, entry: &str, source: String) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(&format!("fisheye.{entry}")),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}

/// Creates the compute pipeline for `entry_point` of the WGSL file `file`, specialised by the
/// override `constants`. With no `layouts` the layout is derived from the shader; passes whose
/// kernels leave a binding unused in some specialisation give theirs explicitly, in group
/// order.
pub fn compute_pipeline(
    device: &wgpu::Device,
    file: &str,
    entry_point: &str,
    constants: &[(&str, f64)],
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::ComputePipeline {
    pipeline_from(device, file, compose(file), entry_point, constants, layouts)
}

/// As [`compute_pipeline`], for a kernel that reads a scene whose arrays are split as
/// `arrays` says (the default for one that reads none), composed with `swaps` (see
/// [`compose_for`]).
pub fn scene_pipeline(
    device: &wgpu::Device,
    file: &str,
    (arrays, swaps): (&SceneArrays, &[(&str, &str)]),
    entry_point: &str,
    constants: &[(&str, f64)],
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::ComputePipeline {
    let source = compose_for(file, arrays, swaps);
    pipeline_from(device, file, source, entry_point, constants, layouts)
}

/// As [`compute_pipeline`], with the composed source passed through `edit` first: WGSL has no
/// override for a storage texture's format, so a pass whose format is chosen at run time
/// rewrites the one its file declares.
pub fn compute_pipeline_edited(
    device: &wgpu::Device,
    file: &str,
    edit: impl FnOnce(String) -> String,
    entry_point: &str,
    constants: &[(&str, f64)],
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::ComputePipeline {
    pipeline_from(
        device,
        file,
        edit(compose(file)),
        entry_point,
        constants,
        layouts,
    )
}

fn pipeline_from(
    device: &wgpu::Device,
    file: &str,
    source: String,
    entry_point: &str,
    constants: &[(&str, f64)],
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::ComputePipeline {
    let label = format!("fisheye.{file}.{entry_point}");
    let layout = (!layouts.is_empty()).then(|| {
        let groups: Vec<Option<&wgpu::BindGroupLayout>> =
            layouts.iter().map(|l| Some(*l)).collect();
        device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&label),
            bind_group_layouts: &groups,
            immediate_size: 0,
        })
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(&label),
        layout: layout.as_ref(),
        module: &module_from(device, file, source),
        entry_point: Some(entry_point),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        },
        cache: None,
    })
}

/// Checks that the WGSL struct `name` of the module `file` has the given size and, in order,
/// the given members at the given byte offsets (naga's layout): Rust structs that mirror WGSL
/// ones call this with their `size_of` and `offset_of!`s.
#[cfg(test)]
pub(crate) fn assert_wgsl_layout(file: &str, name: &str, size: usize, fields: &[(&str, usize)]) {
    let source = compose(file);
    let module = naga::front::wgsl::parse_str(&source).unwrap();
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name} in {file}"));
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("{name} is not a struct");
    };
    assert_eq!(layouter[handle].size as usize, size, "size of {name}");
    let wgsl: Vec<(&str, usize)> = members
        .iter()
        .map(|m| (m.name.as_deref().unwrap_or(""), m.offset as usize))
        .collect();
    assert_eq!(wgsl, fields, "members of {name}");
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parses and validates every WGSL file, composed with its imports, with naga: no GPU;
    /// those that read a scene also with its arrays split into several bindings.
    #[test]
    fn every_wgsl_file_validates() {
        let split = SceneArrays::plan(1 << 20, 30_000, 50_000, 200_000);
        let reads_scene = |name: &str| compose(name).contains("// ---- scene_arrays\n");
        let readers: Vec<&str> = FILES
            .iter()
            .map(|(name, _)| *name)
            .filter(|name| reads_scene(name))
            .collect();
        for kernel in [
            "trace",
            "trace_rq",
            "adaptive",
            "adaptive_rq",
            "cast",
            "raster",
            "raster_multiview",
        ] {
            assert!(readers.contains(&kernel), "{kernel} reads the scene");
        }
        let sources = FILES.iter().map(|(name, _)| (*name, compose(name))).chain(
            readers
                .iter()
                .map(|name| (*name, compose_for(name, &split, &[]))),
        );
        for (name, source) in sources {
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        }
    }

    #[test]
    fn every_file_is_listed() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/wgsl");
        let mut on_disk: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "wgsl"))
            .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
            .collect();
        on_disk.sort();
        let mut listed: Vec<String> = FILES.iter().map(|(n, _)| n.to_string()).collect();
        listed.sort();
        assert_eq!(on_disk, listed, "wgsl/ and shader::FILES disagree");
    }

    #[test]
    fn a_swap_replaces_an_import_and_enables_come_first() {
        let source = compose("trace_rq");
        assert!(source.starts_with("enable wgpu_ray_query;\n"));
        assert_eq!(source.matches("enable ").count(), 1);
        assert!(source.contains("// ---- wgsl/bvh_rq.wgsl"));
        assert!(!source.contains("// ---- wgsl/bvh.wgsl"));
        // Everything else of the software kernel is there, once.
        for shared in ["trace", "shade", "surface", "triangles", "primary", "lens"] {
            let header = format!("// ---- wgsl/{shared}.wgsl\n");
            assert_eq!(source.matches(&header).count(), 1, "{shared}");
        }
    }

    /// A pipeline reading the direction table is composed with `primary_table` in place of
    /// `primary`: the table's binding is in that kernel alone.
    #[test]
    fn the_direction_table_is_bound_only_where_it_is_read() {
        let table = "@group(0) @binding(1) var<storage, read> table";
        let computed = compose("trace");
        assert!(computed.contains("// ---- wgsl/primary.wgsl"));
        assert!(!computed.contains(table));
        let read = compose_for(
            "trace",
            &SceneArrays::default(),
            &[("primary", "primary_table")],
        );
        assert!(read.contains("// ---- wgsl/primary_table.wgsl"));
        assert!(!read.contains("// ---- wgsl/primary.wgsl"));
        assert_eq!(read.matches(table).count(), 1);
    }

    #[test]
    fn imports_come_once_and_first() {
        let source = compose("lens_points");
        assert_eq!(source.matches("// ---- wgsl/math.wgsl").count(), 1);
        let math = source.find("wgsl/math.wgsl").unwrap();
        let lens = source.find("wgsl/lens.wgsl").unwrap();
        let entry = source.find("wgsl/lens_points.wgsl").unwrap();
        assert!(math < lens && lens < entry);
        assert!(!source.contains("#import"));
    }
}
