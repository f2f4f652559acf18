//! Scene arrays split across storage bindings. A binding holds at most
//! `max_storage_buffer_binding_size` bytes (128 MiB on lavapipe and by WebGPU's default), far
//! less than a buffer may (2 GiB there), so the three arrays that grow with the scene (BVH
//! nodes, triangles, per-vertex shading data) are stored in as many bindings as they need:
//! chunks of a power of two of elements, so that finding an element's chunk is a shift.
//!
//! The WGSL that declares them and reads them ([`SceneArrays::wgsl`]: `node_word`,
//! `triangle_at`, `vertex_at`) is generated here for each split and composed into every
//! kernel that reads the scene (`shader::compose_for`); a scene that fits one binding per
//! array gets the plain declarations and reads, as if nothing were split.

use std::fmt::Write;

/// Bytes of one BVH node (obvhs's `CwBvhNode`; WGSL reads it as five `vec4<u32>`).
pub const NODE_BYTES: u64 = 80;
/// Bytes of one triangle as the traversal reads it (`shared::GpuTriangle`).
pub const TRIANGLE_BYTES: u64 = 48;
/// Bytes of one `vec4<f32>` of shading data (vertex normals and UVs).
pub const VERTEX_BYTES: u64 = 16;

/// Where the bindings beyond each array's first begin in group 1 (the scene's group): its
/// fixed bindings are 0 to 4 (see `trace::GpuScene`).
pub const FIRST_EXTRA_BINDING: u32 = 5;

/// How one array is stored: in `chunks` bindings of `1 << shift` elements each (the last one
/// shorter). One chunk holds the whole array, whatever its length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Split {
    /// log2 of the elements a chunk holds (unused with one chunk).
    pub shift: u32,
    /// Bindings the array takes, at least one.
    pub chunks: u32,
}

impl Split {
    /// The whole array in one binding.
    pub const WHOLE: Split = Split {
        shift: 31,
        chunks: 1,
    };

    /// The split of `len` elements of `bytes` each into bindings of at most `limit` bytes:
    /// one chunk if it fits, else chunks of the largest power of two of elements that fits.
    pub fn of(len: u64, bytes: u64, limit: u64) -> Self {
        if len * bytes <= limit {
            return Self::WHOLE;
        }
        let per_chunk = (limit / bytes).max(1);
        let shift = per_chunk.ilog2();
        Self {
            shift,
            chunks: len.div_ceil(1 << shift) as u32,
        }
    }

    /// The element ranges of each chunk of an array of `len` elements.
    pub fn ranges(&self, len: usize) -> Vec<std::ops::Range<usize>> {
        // One chunk holds everything, whatever the shift says.
        let size = if self.chunks == 1 {
            len.max(1)
        } else {
            1usize << self.shift
        };
        (0..self.chunks as usize)
            .map(|c| c * size..((c + 1) * size).min(len))
            .collect()
    }
}

/// How a scene's growing arrays are split across the bindings of group 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneArrays {
    /// The BVH's nodes (80 bytes each).
    pub nodes: Split,
    /// The triangles (48 bytes each).
    pub triangles: Split,
    /// The `vec4<f32>`s of per-vertex shading data.
    pub vertices: Split,
}

impl Default for SceneArrays {
    /// One binding each.
    fn default() -> Self {
        Self {
            nodes: Split::WHOLE,
            triangles: Split::WHOLE,
            vertices: Split::WHOLE,
        }
    }
}

/// The three arrays: their WGSL name, element type, and the accessor that reads them.
const ARRAYS: [(&str, &str); 3] = [
    ("bvh_nodes", "array<vec4<u32>>"),
    ("bvh_triangles", "array<BvhTriangle>"),
    ("vertex_data", "array<vec4<f32>>"),
];

/// The first binding of each array (its chunk 0), as `wgsl/bvh.wgsl` and `wgsl/surface.wgsl`
/// numbered them before they were split.
const FIRST_BINDINGS: [u32; 3] = [0, 1, 3];

impl SceneArrays {
    /// The split of a scene with `nodes` BVH nodes, `triangles` stored triangles and
    /// `vertex_vectors` shading `vec4`s on an adapter whose bindings hold `limit` bytes.
    pub fn plan(limit: u64, nodes: u64, triangles: u64, vertex_vectors: u64) -> Self {
        Self {
            nodes: Split::of(nodes, NODE_BYTES, limit),
            triangles: Split::of(triangles, TRIANGLE_BYTES, limit),
            vertices: Split::of(vertex_vectors, VERTEX_BYTES, limit),
        }
    }

    fn splits(&self) -> [Split; 3] {
        [self.nodes, self.triangles, self.vertices]
    }

    /// Storage bindings beyond one per array.
    pub fn extra_bindings(&self) -> u32 {
        self.splits().iter().map(|s| s.chunks - 1).sum()
    }

    /// Whether any array takes more than one binding.
    pub fn is_split(&self) -> bool {
        self.extra_bindings() > 0
    }

    /// The binding of each array's chunk `c` in group 1: chunk 0 where the array always was,
    /// the others from [`FIRST_EXTRA_BINDING`] on, nodes' first, then triangles', then the
    /// shading data's.
    pub fn bindings(&self) -> [Vec<u32>; 3] {
        let mut next = FIRST_EXTRA_BINDING;
        let splits = self.splits();
        std::array::from_fn(|a| {
            let mut out = vec![FIRST_BINDINGS[a]];
            for _ in 1..splits[a].chunks {
                out.push(next);
                next += 1;
            }
            out
        })
    }

    /// The WGSL module `scene_arrays`: the arrays' bindings and their readers
    /// `node_word(node, word)` (word `word` of five of node `node`), `triangle_at(slot)` and
    /// `vertex_at(index)`.
    pub fn wgsl(&self) -> String {
        let mut out = String::new();
        writeln!(
            out,
            "// Generated by fisheye_rt::split for chunks of nodes, triangles and shading data: \
             {:?}",
            self.splits().map(|s| s.chunks)
        )
        .unwrap();
        // Chunk c of the triangles holds slots from c << shift on (ray queries number a hit
        // by its chunk and its index there).
        writeln!(
            out,
            "const TRIANGLE_CHUNK_SHIFT: u32 = {}u;",
            self.triangles.shift
        )
        .unwrap();
        let bindings = self.bindings();
        for (a, (name, ty)) in ARRAYS.iter().enumerate() {
            for (c, binding) in bindings[a].iter().enumerate() {
                writeln!(
                    out,
                    "@group(1) @binding({binding}) var<storage, read> {}: {ty};",
                    chunk_name(name, c)
                )
                .unwrap();
            }
        }
        let readers = [
            (
                "node_word(node: u32, word: u32) -> vec4<u32>",
                "node",
                "5u * ",
                " + word",
            ),
            ("triangle_at(slot: u32) -> BvhTriangle", "slot", "", ""),
            ("vertex_at(index: u32) -> vec4<f32>", "index", "", ""),
        ];
        for (a, (signature, index, scale, add)) in readers.iter().enumerate() {
            let split = self.splits()[a];
            let name = ARRAYS[a].0;
            writeln!(out, "fn {signature} {{").unwrap();
            if split.chunks == 1 {
                writeln!(out, "    return {name}[{scale}{index}{add}];").unwrap();
            } else {
                let mask = (1u32 << split.shift) - 1;
                writeln!(out, "    let chunk = {index} >> {}u;", split.shift).unwrap();
                writeln!(out, "    let local = {scale}({index} & {mask}u){add};").unwrap();
                for c in 1..split.chunks as usize {
                    writeln!(
                        out,
                        "    if chunk == {c}u {{ return {}[local]; }}",
                        chunk_name(name, c)
                    )
                    .unwrap();
                }
                writeln!(out, "    return {name}[local];").unwrap();
            }
            writeln!(out, "}}").unwrap();
        }
        out
    }
}

/// The WGSL name of chunk `c` of array `name`: the array's own for chunk 0.
fn chunk_name(name: &str, c: usize) -> String {
    if c == 0 {
        name.to_string()
    } else {
        format!("{name}_{c}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_that_fit_take_one_binding_and_others_power_of_two_chunks() {
        assert_eq!(Split::of(10, 48, 480).chunks, 1);
        // 11 triangles in 480 bytes: 8 a chunk (10 fit, the power of two below is 8).
        let s = Split::of(11, 48, 480);
        assert_eq!((s.shift, s.chunks), (3, 2));
        assert_eq!(s.ranges(11), vec![0..8, 8..11]);
        // An element larger than the limit still gets a chunk of one (the upload refuses it).
        assert_eq!(Split::of(3, 48, 16).chunks, 3);
        let arrays = SceneArrays::plan(1 << 20, 30_000, 50_000, 10);
        // 30,000 nodes of 80 bytes in 8192-node chunks; 50,000 triangles in 16384s.
        assert_eq!((arrays.nodes.shift, arrays.nodes.chunks), (13, 4));
        assert_eq!((arrays.triangles.shift, arrays.triangles.chunks), (14, 4));
        assert_eq!(arrays.vertices.chunks, 1);
        assert_eq!(arrays.extra_bindings(), 6);
        assert_eq!(
            arrays.bindings(),
            [vec![0, 5, 6, 7], vec![1, 8, 9, 10], vec![3]]
        );
    }

    #[test]
    fn every_chunk_is_declared_once_and_read() {
        let arrays = SceneArrays::plan(1 << 20, 30_000, 50_000, 200_000);
        let wgsl = arrays.wgsl();
        let bindings: Vec<u32> = arrays.bindings().into_iter().flatten().collect();
        for b in &bindings {
            assert_eq!(wgsl.matches(&format!("@binding({b})")).count(), 1, "{wgsl}");
        }
        for name in ["bvh_nodes_3", "bvh_triangles_3", "vertex_data_3"] {
            assert!(wgsl.contains(&format!("return {name}[local]")), "{wgsl}");
        }
        assert!(!SceneArrays::default().wgsl().contains("let chunk"));
    }
}
